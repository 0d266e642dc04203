#include "tools/bench_recognizer.hpp"

#include <cstdio>
#include <cstring>

namespace sh::tools {
namespace {

void LogBench(const char* line) { std::fprintf(stderr, "stereohash bench: %s\n", line); }

}  // namespace

ObjectRecognizerConfig TunedRecognizerConfig(const PipelineConfig& tuned,
                                             const MonoPipelineConfig& mono_tuned,
                                             int64_t (*now_ns)()) {
  ObjectRecognizerConfig config;
  config.stereo_preset = &tuned;
  config.mono_preset = &mono_tuned;
  config.threads = tuned.threads;
  config.rgb_frames = tuned.rgb_frames;
  config.table_known = tuned.table.known;
  config.left_T_table = tuned.table.left_T_table;
  config.table_estimate = tuned.table_estimate.enabled;
  config.table_carry = tuned.table_carry.enabled;
  config.table_confirm_frames = tuned.table_carry.confirm_frames;
  config.table_check_frames = tuned.table_carry.check_every_frames;
  config.now_ns = now_ns;
  config.log = &LogBench;
  return config;
}

Status MakeBenchRecognizer(const ObjectRecognizerConfig& config, BenchRecognizer* out) {
  out->paths = MakeZeroed<RecognitionPaths>();  // resident as used (docs/memory.md)
  if (out->paths == nullptr) {
    return Status::Error(StatusCode::kUnavailable, "cannot allocate the recognition paths");
  }
  SH_RETURN_IF_ERROR(out->paths->Allocate(/*printed=*/false, /*one_camera=*/true));
  out->recognizer = std::make_unique<ObjectRecognizer>(out->paths->set(), config);
  out->output = std::make_unique<RecognitionOutput>();
  return Status::Ok();
}

bool SameModels(const AspectTableView& aspects, const TableView& tables) {
  bool same = aspects.model_count() == tables.model_count();
  for (uint32_t m = 0; same && m < tables.model_count(); ++m) {
    same = std::strcmp(aspects.model(m).name, tables.model(m).name) == 0;
  }
  return same;
}

}  // namespace sh::tools
