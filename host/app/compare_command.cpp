// obscura compare A.exr B.exr [--channel combined.R] — the error of image A against image B
// [SPEC §4]: RMSE and relMSE over the three channels from --channel. For noise and speed-against-
// error studies from the shell (e.g. two seeds of the same render: their RMSE is sqrt(2) x noise).
#include <stdexcept>

#include <fmt/core.h>

#include "analysis/image_error.h"
#include "app/commands.h"
#include "core/error.h"
#include "io/image_io.h"

namespace obscura::app {

void addCompareCommand(CLI::App& app) {
  struct Options {
    std::string image, reference, channel = "combined.R";
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("compare", "Error (RMSE, relMSE) of an image against a reference image");
  cmd->add_option("image", o->image, "the image (EXR as obscura writes it)")->required();
  cmd->add_option("reference", o->reference, "the reference image")->required();
  cmd->add_option("--channel", o->channel, "first of the three channels compared (default combined.R)");
  cmd->callback([o] {
    const io::Image a = io::readImage(o->image), b = io::readImage(o->reference);
    try {
      const analysis::ImageError e = analysis::imageError(a, b, o->channel);
      fmt::print("rmse {:.6g} relmse {:.6g}\n", e.rmse, e.relMse);
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{} against {}: {}", o->image, o->reference, e.what()));
    }
  });
}

} // namespace obscura::app
