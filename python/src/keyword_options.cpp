#include "keyword_options.h"

#include <fmt/format.h>

#include "app/commands.h"
#include "app/render_frame.h"
#include "core/error.h"

namespace obscura::python {

app::RenderOptions renderOptions(const std::vector<std::string>& arguments, OptionSet set, const std::string& caller) {
  app::RenderOptions o;
  CLI::App cli{caller};
  if (set == OptionSet::Frame) app::useStillImageDefaults(o); // as `obscura render`
  app::addRenderOptions(cli, o);
  if (set == OptionSet::Frame) app::addFrameOptions(cli, o);
  else cli.add_option("--exposure", o.exposure, "exposure of the display image in stops");
  app::addDeviceOptions(cli, o.device);
  std::vector<std::string> reversed(arguments.rbegin(), arguments.rend()); // CLI11 takes them last first
  try {
    cli.parse(reversed);
  } catch (const CLI::ParseError& e) {
    throw InputError(fmt::format("{}: {}", caller, e.what()));
  }
  return o;
}

} // namespace obscura::python
