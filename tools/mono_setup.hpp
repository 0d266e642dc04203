// What `stereohash recognize` and `stereohash bench recorded` need for the monocular mode: the
// aspect table, the configuration from the recognition options, the result as text and JSON.
#pragma once

#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/mono/mono_pipeline.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tables/aspect_file.hpp"
#include "tools/recognize_setup.hpp"

namespace sh::tools {

// The aspect table: the --aspects file, the ASPECTS_2D section of the --tables model set, or the
// built-in one.
struct LoadedAspects {
  MappedAspectTable mapped;
  AspectTableView view;
};
// `required`: the one-camera mode, which recognises with the aspect table alone: a --tables
// file without one is refused (rather than the built-in table silently used for other models).
Status LoadAspects(const RecognizeOptions& options, LoadedAspects* out, bool required = false);

// The monocular configuration for the options: the background preset if one is forced,
// otherwise the automatic one (thresholds measured from the image).
MonoPipelineConfig MakeMonoConfig(const RecognizeOptions& options);

// `--set mono.NAME=VALUE` of the bench commands: vote, search and acceptance settings of the
// monocular recogniser. An unknown name, or a value that is not of the setting's kind, is an
// error naming it, and the configuration is left as it was.
Status ApplyMonoSetting(const char* setting, MonoPipelineConfig* config);

// The names ApplyMonoSetting knows, for the commands' help (as PipelineSettingNames).
std::string MonoSettingNames(const char* indent, size_t width);

// One line per object, the feature and search counts, the stage times.
void PrintMonoResult(const AspectTableView& aspects, const MonoResult& result, int camera);

// {"frame": "camera", "mode": "monocular", "camera": "left", "objects": [...], "features":
// {...}, "recognition": {...}, "table": {...}, "time_ms": {...}}
std::string MonoResultJson(const AspectTableView& aspects, const MonoResult& result,
                           const TableChoice& table, int camera);

// The camera's image with the recognised models' visible edges in their colours (packed RGB
// rows, the image's size).
Status BuildMonoOverlay(const MonoPipeline& pipeline, const AspectTableView& aspects,
                        const MonoResult& result, ConstGrayView image, std::vector<uint8_t>* rgb,
                        int* width, int* height);

}  // namespace sh::tools
