// stereohash: host command-line program (and stereohash-cv, see PrintUsage). Each subcommand
// lives in its own cmd_*.cpp file and registers itself (tools/command.cpp).
#include <cstdio>
#include <cstring>

#include "tools/command.hpp"

namespace sh::tools {
namespace {

// stereohash and stereohash-cv (the commands built with OpenCV, tools/cv_program.hpp) share this
// file; STEREOHASH_PROGRAM names the one being built.
#ifndef STEREOHASH_PROGRAM
#define STEREOHASH_PROGRAM "stereohash"
#endif

void PrintUsage() {
  std::printf("usage: " STEREOHASH_PROGRAM " <command> [options]\n");
  if (std::strcmp(STEREOHASH_PROGRAM, "stereohash") == 0) {
    std::printf(
        "Recognises polyhedral objects in calibrated stereo images by 3-D geometric "
        "hashing.\n\n");
  } else {
    std::printf("The stereohash commands built with OpenCV; 'stereohash <command>' runs them.\n\n");
  }
  std::printf("commands:\n");
  ListCommands([](const Command& c) { std::printf("  %-12s %s\n", c.name, c.summary); });
  std::printf("\n'" STEREOHASH_PROGRAM " <command> --help' describes a command.\n");
}

}  // namespace

}  // namespace sh::tools

int main(int argc, char** argv) {
  using namespace sh::tools;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    PrintUsage();
    return argc < 2 ? 2 : 0;
  }
  const Command* command = FindCommand(argv[1]);
  if (command == nullptr) {
    std::fprintf(stderr, STEREOHASH_PROGRAM ": unknown command '%s'\n\n", argv[1]);
    PrintUsage();
    return 2;
  }
  return command->run(argc - 1, argv + 1);
}
