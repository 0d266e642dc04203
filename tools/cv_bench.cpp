// `bench textured` in stereohash-cv: the texture path beside its OpenCV peer. The other benches
// need no OpenCV and stay in stereohash, which runs this one when the peer is wanted.
#include <cstdio>
#include <cstring>

#include "tools/bench_textured.hpp"
#include "tools/command.hpp"

namespace sh::tools {
namespace {

int RunCvBench(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "textured") == 0) return RunBenchTextured(argc, argv);
  std::fprintf(stderr,
               "stereohash-cv bench: only 'bench textured' is here; 'stereohash bench' runs the "
               "others\n");
  return 2;
}

}  // namespace

SH_REGISTER_COMMAND(bench, "printed cartons through the texture path and its OpenCV peer",
                    RunCvBench);

}  // namespace sh::tools
