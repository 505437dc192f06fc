#include "app/command_line.h"

#include <cstdio>
#include <new>

#include <fmt/format.h>

#include "app/commands.h"
#include "core/error.h"

namespace obscura::app {

namespace {

void addCommands(CLI::App& app) {
  app.require_subcommand(1);
  addRenderCommand(app);
  addInfoCommand(app);
  addBenchRaysCommand(app);
  addConvergeCommand(app);
  addRelightCommand(app);
  addCompareCommand(app);
  addViewCommand(app);
  addRecoverCommand(app);
  addRemodelCommand(app);
  addMergeCommand(app);
}

constexpr const char* kDescription = "obscura: ray-traced obscurances and interactive relighting (Vulkan compute)";

} // namespace

void runCommand(const std::vector<std::string>& args) {
  CLI::App app{kDescription};
  addCommands(app);
  std::vector<std::string> reversed(args.rbegin(), args.rend()); // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    throw InputError(fmt::format("{}: {}", args.empty() ? "obscura" : args.front(), e.what()));
  }
}

int runCommandLine(int argc, const char* const* argv) {
  CLI::App app{kDescription};
  addCommands(app);
  // Errors in input are caught here once: nothing else ever ends the program.
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const InputError& e) {
    fmt::print(stderr, "obscura: error: {}\n", e.what());
    return 2;
  } catch (const DeviceError& e) {
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

} // namespace obscura::app
