// The recognition facade (recog/pipeline/object_recognizer.hpp) as the scoring bench commands
// (`bench recorded`, `bench scenes`) run it: set up from a configuration the bench tuned (a
// preset with its --set settings), with the stereo pipeline and the one-camera fallback
// allocated, so that the bench measures the paths the board and `stereohash recognize` run.
#pragma once

#include <cstdint>
#include <memory>

#include "recog/base/status.hpp"
#include "recog/base/zeroed.hpp"
#include "recog/mono/mono_pipeline.hpp"
#include "recog/pipeline/object_recognizer.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/pipeline/recognition_paths.hpp"
#include "tables/aspect_view.hpp"
#include "tables/table_view.hpp"

namespace sh::tools {

// The facade's settings that reproduce `tuned` and `mono_tuned` exactly: they stand in place of
// the preset, and what the facade sets on top of a preset (threads, colour frames, the known
// table, the table estimate and its carrying) is taken from `tuned`; the working volume stays
// tuned's own. Both configurations must outlive the facade. The monocular fallback gets no table
// (mono_table_known false): the caller says when it has one. Changes are logged to stderr.
ObjectRecognizerConfig TunedRecognizerConfig(const PipelineConfig& tuned,
                                             const MonoPipelineConfig& mono_tuned,
                                             int64_t (*now_ns)());

// The facade with its storage: the stereo pipeline and the one-camera fallback (no printed
// cartons' texture path), and room for a frame's output.
struct BenchRecognizer {
  ZeroedPtr<RecognitionPaths> paths;
  std::unique_ptr<ObjectRecognizer> recognizer;
  std::unique_ptr<RecognitionOutput> output;
};
Status MakeBenchRecognizer(const ObjectRecognizerConfig& config, BenchRecognizer* out);

// Whether the aspect table lists the hash tables' models in their order: the benches score the
// monocular mode's poses by model index.
bool SameModels(const AspectTableView& aspects, const TableView& tables);

}  // namespace sh::tools
