// obscura merge PARTS... -o out.{exr,png} | DIR — a farm's parts (render --samples A:B --tile I/T)
// summed into the frame one process would render (host/farm/merge.h); DIR: a relighting state
// for `obscura relight DIR`. --list-missing prints what to render still.
#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "app/commands.h"
#include "core/error.h"
#include "farm/merge.h"
#include "io/image_io.h"
#include "relight/relight_state.h"
#include "render/aovs.h"

namespace obscura::app {
namespace {
namespace fs = std::filesystem;

struct MergeOptions {
  std::vector<std::string> parts;
  std::string output;
  std::string saveState;
  std::vector<std::string> aovs;
  float exposure = 0.0f;
  bool partial = false;
  bool listMissing = false;
};

std::string missingList(const farm::MergedFrame& merged) {
  std::string text;
  for (const auto& piece : merged.missing) text += "\n  " + piece.describe();
  return text;
}

void runMerge(const MergeOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::string> files = farm::partFiles(o.parts);
  if (!o.listMissing && o.output.empty()) throw InputError("merge: -o OUT.exr, OUT.png or a folder is required");
  const std::string ext = io::extensionOf(o.output);
  const bool stateOnly = !o.listMissing && ext != "exr" && ext != "png";
  if (stateOnly && fs::exists(o.output) && !fs::is_directory(o.output))
    throw InputError(fmt::format("{}: the output must be .exr, .png or a folder (for a relighting state)", o.output));
  farm::MergedFrame merged = farm::mergeParts(files);
  if (o.listMissing) {
    for (const auto& piece : merged.missing) {
      const std::string args = piece.renderArguments();
      fmt::print("{}\n", args.empty() ? "# " + piece.describe() + " (rows that are no tile of the parts)" : args);
    }
    return;
  }
  if (!merged.missing.empty() && !o.partial)
    throw InputError(fmt::format("merge: the {} part(s) do not cover the frame; missing:{}\nrender those parts (merge "
                                 "--list-missing prints their options) or give --partial for a preview",
                                 files.size(), missingList(merged)));
  const std::string stateDir = stateOnly ? o.output : o.saveState;
  if (!stateDir.empty()) {
    if (merged.method() != render::Method::Obscurance)
      throw InputError(fmt::format("{}: a relighting state needs parts of --method obscurance (these are {})", stateDir,
                                   nameOf(render::kMethodNames, merged.method())));
    if (!merged.missing.empty())
      throw InputError(fmt::format("{}: a relighting state needs every part (missing:{})", stateDir, missingList(merged)));
  }
  if (!stateOnly) {
    const io::Image image = farm::mergedImage(merged);
    if (ext == "exr") {
      io::writeExr(o.output, render::selectAovs(image, o.aovs));
    } else {
      const std::string first = o.aovs.empty() ? "combined" : o.aovs.front();
      const auto channels = render::aovChannels(first);
      const int c = image.channelIndex(channels.front());
      if (c < 0) throw InputError(fmt::format("--aov {}: the merged frame has no such AOV", first));
      io::writePng(o.output, image, c, o.exposure, static_cast<int>(channels.size()));
    }
  }
  if (!stateDir.empty()) relight::saveState(stateDir, farm::mergedStateJson(merged), farm::mergedTransport(merged));
  std::uintmax_t bytes = 0;
  for (const auto& f : files) bytes += fs::file_size(f);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  fmt::print(stderr, "merge: {} part(s), {:.1f} MiB, {}x{} {} {} spp{}; parts {:.1f} ms GPU, {:.2f} s wall; merged in "
                     "{:.2f} s -> {}{}\n",
             files.size(), static_cast<double>(bytes) / 1048576.0, merged.sums.width, merged.sums.height,
             nameOf(render::kMethodNames, merged.method()), merged.spp(), merged.missing.empty() ? "" : " (PREVIEW: parts missing)",
             merged.partGpuMs, merged.partWallSeconds, seconds, stateOnly ? stateDir : o.output,
             !stateOnly && !stateDir.empty() ? " and " + stateDir : "");
  if (!merged.missing.empty()) fmt::print(stderr, "merge: missing:{}\n", missingList(merged));
}

} // namespace

void addMergeCommand(CLI::App& app) {
  auto o = std::make_shared<MergeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Sum a farm render's parts (render --samples A:B --tile I/T -o part.exr) into one frame: EXR, PNG, or "
               "a folder holding the relighting state");
  cmd->add_option("parts", o->parts, "part files, or folders of them")->required();
  cmd->add_option("-o,--output", o->output,
                  "out.exr (every AOV and light layer), out.png (combined, tonemapped) or a folder (relighting state "
                  "for 'obscura relight DIR')");
  cmd->add_option("--save-state", o->saveState, "also write the relighting state to this folder");
  cmd->add_option("--aov", o->aovs, "AOV(s) to write; the first goes to PNG (default: all / combined)");
  cmd->add_option("--exposure", o->exposure, "PNG exposure in stops");
  cmd->add_flag("--partial", o->partial,
                "write a preview even when parts are missing (their pixels or samples are left out; the missing "
                "parts are listed)");
  cmd->add_flag("--list-missing", o->listMissing,
                "print the render options of every missing part (--tile I/T --samples A:B), one a line, and exit");
  cmd->callback([o] { runMerge(*o); });
}

} // namespace obscura::app
