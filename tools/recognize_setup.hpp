// What `stereohash recognize` and `stereohash bench recorded` share: the recognition options,
// loading the calibration, table pose, images and hash tables, the pipeline configuration made
// from them, and the JSON form of a result. One place, so that the bench runs the pipeline
// exactly as `recognize` does.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/frame.hpp"
#include "recog/image/image.hpp"
#include "recog/pipeline/model_set.hpp"
#include "recog/pipeline/object_recognizer.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "tables/shape_views_file.hpp"
#include "tables/table_file.hpp"
#include "tables/table_view.hpp"

namespace sh::tools {

struct RecognizeOptions {
  const char* tables_path = nullptr;   // hash tables (default: the built-in hash fn 5 tables)
  const char* aspects_path = nullptr;  // aspect table of the monocular mode (default: built-in)
  const char* views_path = nullptr;    // view database of colour parts (shape path)
  const char* table_path = nullptr;    // table.yaml: the table's pose in the left camera
  float budget_ms = 0;                 // 0: no time limit
  const char* background = nullptr;    // "dark" or "light" preset; nullptr: automatic
  int threads = 0;                     // worker threads, the caller included; 0: all cores
};

// Help lines of the options above, for the commands' --help.
extern const char kRecognizeOptionsHelp[];

enum class OptionResult { kTaken, kNotMine, kBadValue };

// One `--option value` of the recognition options; kBadValue prints a message naming `command`.
OptionResult ParseRecognizeOption(const char* command, const char* option, const char* value,
                                  RecognizeOptions* options);

Result<StereoCalibration> LoadCalibration(const char* path);
// The calibration of the frames recognition sees (FrameCalibration): a calibration of a sensor
// larger than kMaxImageWidth x kMaxImageHeight binned as LoadImage bins its images.
Result<StereoCalibration> LoadFrameCalibration(const char* path);
Result<RigidTransform> LoadTablePose(const char* path);

struct LoadedImage {
  std::vector<uint8_t> pixels;  // grey, or RGB for colour files
  std::vector<uint8_t> grey;    // grey of a colour file (BT.601 luma weights)
  ConstGrayView view;           // grey
  FrameView frame;              // as the file holds it: grey or RGB
  int bin = 1;                  // the file's image binned by this factor (BinFactorFor)
  int file_width = 0;           // the file's image size, before binning
  int file_height = 0;
};
// Reads a PNG or PGM, grey or colour, up to kMaxSensorWidth x kMaxSensorHeight; an image larger
// than a pipeline frame is binned by BinFactorFor() to fit. `which` ("left") goes into messages.
Status LoadImage(const char* path, const char* which, LoadedImage* out);
// "image 2592x2048 binned 2 x 2 to 1296x1024 (the calibration alike)" for a binned image;
// nothing otherwise.
void PrintBinning(const LoadedImage& image);

// The model set: hash tables (a mapped file, or the built-in ones unless only a view database
// is given) and the view database of colour parts (a mapped file, optional).
struct LoadedTables {
  MappedTable mapped;
  TableView view;
  MappedShapeViews views;
  const ShapeViewsView* shape() const { return views.view().empty() ? nullptr : &views.view(); }
  ModelSet models() const { return ModelSet(&view, shape()); }
};
Status LoadTables(const RecognizeOptions& options, LoadedTables* out);

// The table pose in use and where it came from.
struct TableChoice {
  bool present = false;
  RigidTransform left_T_table;
  std::string source;  // file name, or empty
};

// The pipeline configuration for the options: the preset (or the automatic default) and, with
// a table pose, the working volume over the table.
PipelineConfig MakePipelineConfig(const RecognizeOptions& options, const TableChoice& table);

// The recognition facade's settings for the options, as the board's keys give them: the preset,
// the threads, the table pose (the stereo path's table and the space over it) and the aspect
// table of the one-image rescue (--aspects, else the --tables model set's). `rig_T_table`, when
// no table pose is given: the rig's own table (a recording's rig_table.yaml), which the rescue
// lays its objects onto but which is no table of the scene. Each pair stands alone: no plane is
// carried between pairs.
ObjectRecognizerConfig MakeRecognizerConfig(const RecognizeOptions& options,
                                            const TableChoice& table,
                                            const RigidTransform* rig_T_table);

// `--set name=value` of the bench commands: one of the settings worth exploring (shape.*,
// verify.*, recognizer.*, stereo.*, features.*, table_estimate.*, table_carry.*). An unknown
// name, or a value that is not a number of the setting's kind (a finite number, a whole number,
// 0 or 1), is an error naming it, and the configuration is left as it was.
Status ApplyPipelineSetting(const char* setting, PipelineConfig* config);

// The names ApplyPipelineSetting knows, for the commands' help: lines of at most `width`
// characters, each starting with `indent`, separated by newlines.
std::string PipelineSettingNames(const char* indent, size_t width);

// The table pose of --table (present = false without a path).
Result<TableChoice> LoadTableChoice(const char* path);

// The fields every path's objects start with: "model": NAME, "R": [[...]], "t": [...] (no braces),
// so that the polyhedral, carton and colour objects name their pose alike.
std::string PoseJsonFields(const char* model_name, const RigidTransform& cam_T_model);

// One recognised object as JSON: {"model": ..., "R": ..., "t": ..., "vote": ..., "verify": ...}.
std::string ObjectJson(const char* model_name, const RecognizedObject& o);

// One recognised object as a line of the printed table (index, model, t, rotation vector in
// degrees, vote, the two verify scores).
void PrintObjectLine(size_t index, const char* model_name, const RecognizedObject& o);

// {"frame": "camera", "objects": [...], "features": {...}, "recognition": {...}, "time_ms": {...},
// "table": ...}
std::string ResultJson(const ModelSet& models, const PipelineResult& result,
                       const TableChoice& table, int threads);

int64_t NowNs();
// This process's CPU time (all threads), nanoseconds: stage times that a loaded machine does not
// stretch (for one thread of work; parallel stages add up their threads).
int64_t CpuNs();

}  // namespace sh::tools
