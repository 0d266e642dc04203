// `stereohash bench recorded DIR`: recorded stereo scenes with ground truth through the pipeline.
#pragma once

namespace sh::tools {

// argv[0] = "bench", argv[1] = "recorded"; returns the exit code.
int RunBenchRecorded(int argc, char** argv);

}  // namespace sh::tools
