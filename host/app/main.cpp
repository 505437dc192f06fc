// obscura — ray-traced obscurances and interactive relighting on Vulkan compute.
// The command line is app::runCommandLine (app/command_line.h): input errors exit 2 with a
// message naming the file and the problem, device failures 3.
#include "app/command_line.h"

int main(int argc, char** argv) { return obscura::app::runCommandLine(argc, argv); }
