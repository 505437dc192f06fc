// command_line.h — the whole `obscura` command line as a function: the subcommands registered,
// argv parsed and the command run, and every error turned into what a user sees (a message
// naming the file and the problem, exit 2 for bad input, 3 for the device, 4 for a bug).
// main() is this; the CLI tests call it in-process (tests/app/cli_runner.h).
#pragma once

namespace obscura::app {

int runCommandLine(int argc, const char* const* argv);

} // namespace obscura::app
