// `stereohash bench textured`: printed cartons through the texture path and an OpenCV peer.
#pragma once

namespace sh::tools {

// argv[0] = "bench", argv[1] = "textured"; returns the exit code.
int RunBenchTextured(int argc, char** argv);

}  // namespace sh::tools
