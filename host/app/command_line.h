// command_line.h — the whole `obscura` command line as a function: the subcommands registered,
// argv parsed and the command run, and every error turned into what a user sees (a message
// naming the file and the problem, exit 2 for bad input, 3 for the device, 4 for a bug).
// main() is this; the CLI tests call it in-process (tests/app/cli_runner.h).
#pragma once
#include <string>
#include <vector>

namespace obscura::app {

int runCommandLine(int argc, const char* const* argv);

// One command (`args` without the program's name: {"recover", SCENE, "--photos", ...}) run with
// its errors thrown instead of printed: InputError (a CLI::ParseError's message becomes one),
// DeviceError, ... What the Python API drives `recover` and `remodel` through, so that its keyword
// arguments are the command's options, checked and reported the same way.
void runCommand(const std::vector<std::string>& args);

} // namespace obscura::app
