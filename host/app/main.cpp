// obscura — ray-traced obscurances and interactive relighting on Vulkan compute.
// Errors in input are caught here once: a message naming the file and the problem, exit 2;
// device failures exit 3. Nothing else ever ends the program.
#include <cstdio>

#include <fmt/core.h>

#include "app/commands.h"
#include "core/error.h"


int main(int argc, char** argv) {
  CLI::App app{"obscura: ray-traced obscurances and interactive relighting (Vulkan compute)"};
  app.require_subcommand(1);
  obscura::app::addRenderCommand(app);
  obscura::app::addInfoCommand(app);
  obscura::app::addBenchRaysCommand(app);
  obscura::app::addConvergeCommand(app);
  obscura::app::addRelightCommand(app);
  obscura::app::addCompareCommand(app);
  obscura::app::addViewCommand(app);
  obscura::app::addRecoverCommand(app);
  obscura::app::addRemodelCommand(app);
  obscura::app::addMergeCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const obscura::InputError& e) {
    fmt::print(stderr, "obscura: error: {}\n", e.what());
    return 2;
  } catch (const obscura::DeviceError& e) {
    fmt::print(stderr, "obscura: device error: {}\n", e.what());
    return 3;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "obscura: out of host memory (a smaller --width/--height or scene needs less)\n");
    return 3;
  } catch (const vk::SystemError& e) {
    fmt::print(stderr, "obscura: Vulkan error: {}\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "obscura: internal error: {}\n", e.what());
    return 4;
  }
  return 0;
}
