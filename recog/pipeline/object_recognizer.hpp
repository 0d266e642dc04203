// The one recognition facade: every path a frame can take, composed in one place. A stereo pair
// goes to the printed cartons' texture path first (its objects hidden from the next paths), then
// to the stereo pipeline (the colour parts' shape path, the polyhedral search and its one-image
// rescue); one camera's frame, when the other camera failed, goes to the monocular pipeline. The
// model mask, the time budget, the table the objects stand on and the rescue's recogniser are
// handled here, and the result is neutral: model id, pose, score and the path that found each
// object. The firmware maps it to CAN/CANopen and JSON; `stereohash recognize` prints it.
#pragma once

#include <atomic>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/base/vector.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/image/frame.hpp"
#include "recog/image/image.hpp"
#include "recog/pipeline/model_set.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/pipeline/recognition_paths.hpp"
#include "recog/pipeline/table_carry.hpp"
#include "tables/aspect_file.hpp"
#include "tables/aspect_view.hpp"

namespace sh {

// The settings of every path (docs/pipeline.md); the firmware's keys and the recognise command's
// options fill them.
struct ObjectRecognizerConfig {
  bool automatic = true;          // thresholds measured from each image (no preset)
  bool light_background = false;  // without `automatic`: the light-table preset
  int threads = 0;                // worker threads, the calling one included; 0 = all cores
  bool rgb_frames = true;         // the camera may hand over RGB frames (PipelineConfig)
  bool table_known = false;       // left_T_table is the table the objects stand on
  // Without table_known: the plane the objects found rest on, estimated in each frame, and
  // carried between frames once confirmed (firmware key table_estimate; PipelineConfig).
  bool table_estimate = true;
  bool table_carry = true;
  // With table_carry: agreeing estimates that confirm the plane, and carried frames between two
  // checks by a fresh estimate (firmware keys table_confirm_frames, table_check_frames).
  uint32_t table_confirm_frames = TableCarryConfig{}.confirm_frames;
  uint32_t table_check_frames = TableCarryConfig{}.check_every_frames;
  bool volume_set = false;  // working volume box, in the left camera or the table frame
  float volume_min_mm[3] = {0, 0, 0};
  float volume_max_mm[3] = {0, 0, 0};
  bool volume_in_table_frame = false;
  // No box given but a table pose known: the space over the table (WorkingVolume::OverTable),
  // as `stereohash recognize --table` bounds it.
  bool volume_over_table = false;
  RigidTransform left_T_table;  // table (conveyor) frame -> left camera, mm
  // When set, read at each Init() in place of left_T_table: the simulator's rendered table,
  // known only once its world is built.
  const RigidTransform* left_T_table_at_init = nullptr;
  // The monocular fallback lays objects onto this table (left_T_table or left_T_table_at_init):
  // a configured table pose, or the simulator's rendered one. Without it, onto the plane the
  // stereo frames confirmed and carried before the camera failed (table_carry), else no poses:
  // one image cannot tell depth (kMonoNeedsTablePlane).
  bool mono_table_known = false;
  // A model set (the `tables` file) whose ASPECTS_2D section, if it has one, replaces the
  // linked-in aspect table of the monocular fallback; nullptr: the linked-in one.
  const char* aspects_file = nullptr;
  // In place of the preset (automatic, light, dark) when set: a configuration the caller tuned
  // (the bench's --set settings on a preset). The settings above still apply on top of it.
  const PipelineConfig* stereo_preset = nullptr;
  const MonoPipelineConfig* mono_preset = nullptr;
  // The monotonic clock of the timings and the budget (nanoseconds); null: no timings, and only
  // the scene-basis budget bounds the search.
  int64_t (*now_ns)() = nullptr;
  // Where the facade says what changed in the cell (a table plane confirmed or dropped, the
  // rescue on or off), one line without a newline; only on a change, never per frame. Null:
  // silent.
  void (*log)(const char* line) = nullptr;
};

// The path that found an object.
enum class RecognitionPath : uint8_t {
  kPolyhedra = 0,  // 3-D geometric hashing of corners and edges (with its one-image rescue)
  kColourParts,    // the shape path on colour frames
  kPrinted,        // the texture path of printed cartons
  kOneCamera,      // the monocular fallback (the other camera failed)
};
const char* RecognitionPathName(RecognitionPath path);

// One object found: a model of the model set, its pose in the left camera frame and how well
// the images confirm it.
struct FoundObject {
  RigidTransform cam_T_model;  // model frame -> left camera, mm
  uint32_t model = 0;          // ModelSet id: polyhedra, colour parts, printed models
  uint32_t instance = 0;       // counts the objects of one model in the frame
  float score = 0;             // 0..1: the weaker image's verification (print ZNCC for cartons)
  RecognitionPath path = RecognitionPath::kPolyhedra;
};

// Capacity: every stereo object and every carton of a frame.
inline constexpr size_t kMaxFoundObjects = kMaxObjects + kMaxRecognitionCartons;

// What a frame gave, whichever path ran.
struct RecognitionOutput {
  // The stereo pipeline's objects (polyhedra, then colour parts), then the printed cartons; the
  // model mask applied. One camera: that camera's objects.
  Vector<FoundObject, kMaxFoundObjects> objects;
  bool budget_hit = false;  // the polyhedral search stopped at the time budget
  bool one_camera = false;  // found by the monocular fallback
  // The table the frame used, and its pose when it has one (stereo frames; one camera reports
  // the source only).
  TableSource table_source = TableSource::kNone;
  RigidTransform left_T_table;
  PipelineTimings time;  // the stereo pipeline's stages (zero for one camera)
};

// What the stereo pipeline's one-image rescue (docs/pipeline.md, stage 4d) did since start, on the
// fallback's recogniser: how often it was lent (at Init, back from a fallback on the right
// camera, after a model mask change), the stereo frames processed with it lent, those in which
// its gate let it run (enough left-image corners no accepted object explains), the objects its
// one-image search found and those confirmed in both images and reported.
struct RescueCounters {
  uint64_t lends = 0;
  uint64_t frames_lent = 0;
  uint64_t frames_ran = 0;
  uint64_t found = 0;
  uint64_t added = 0;
};

// A stereo pair as the camera delivered it: the frames in their format (the colour parts' path
// reads their colour) and their grey images (the printed cartons' path reads those).
struct StereoInput {
  FrameView left, right;
  ConstGrayView left_grey, right_grey;
};

class ObjectRecognizer {
 public:
  // `paths` (RecognitionPaths): the stereo pipeline, and optionally the texture path (printed
  // models; without it a model set holding them fails Init) and the monocular fallback
  // (without it ProcessMonocular fails). All outlive the facade.
  ObjectRecognizer(const RecognitionPathSet& paths, const ObjectRecognizerConfig& config)
      : paths_(paths), config_(config) {}

  // Sets every path up for the calibration and the model set (the hash tables, the colour parts'
  // view database, the printed models' feature database; valid until the next Init). May
  // allocate: at boot and after a cleared data fault only.
  Status Init(const StereoCalibration& calib, const ModelSet& models, uint32_t model_mask);
  // Restricts the objects reported to the models whose bits are set (ModelSet ids < 32). Keeps
  // the carried table plane. No allocation.
  Status SetModelMask(uint32_t model_mask);
  // A stereo pair through every path, within budget_ms (<= 0: no limit). No allocation.
  Status Process(const StereoInput& pair, float budget_ms, RecognitionOutput* out);
  // One camera's grey frame (0 left, 1 right; the other camera failed) through the monocular
  // fallback: poses in the left camera frame. Without a configured table or a carried plane
  // there are no poses (kFailedPrecondition, kMonoNeedsTablePlane). No allocation.
  Status ProcessMonocular(int camera, ConstGrayView image, float budget_ms, RecognitionOutput* out);

  // Whether ProcessMonocular works (the fallback is configured and set up).
  bool monocular() const;
  // The monocular pipeline lays objects onto the stereo frames' carried plane (no table pose
  // configured; the plane was confirmed before the fallback).
  bool mono_on_carried_plane() const { return mono_on_carried_plane_; }
  // The monocular fallback's aspect table (valid after Init).
  const AspectTableView& aspects() const { return aspects_; }
  // The rescue's counters (written by the thread that calls Process, read by any) and whether
  // the fallback's recogniser is lent to it now.
  RescueCounters rescue_counters() const;
  bool rescue_lent() const { return rescue_lent_.load(std::memory_order_relaxed); }
  // The last stereo frame's pipeline result (features, stages, table, rescue), for diagnostics.
  const PipelineResult& stereo_result() const { return result_; }
  // The last stereo frame's printed cartons (the texture path's result), or null when it did not
  // run (no printed models, or the mask selects none).
  const texture::TextureResult* printed_result() const {
    return printed_ran_ ? paths_.texture_result : nullptr;
  }
  const Pipeline& pipeline() const { return *paths_.stereo; }
  // The last one-camera frame's result (features, stages), for diagnostics.
  const MonoResult* mono_result() const { return paths_.mono_result; }
  // Diagnosis only (bench tools): the monocular pipeline of that frame, for its features and its
  // recogniser's Diagnose at the true poses (which overwrites the search state; the next frame
  // sets it again). Null without the fallback.
  MonoPipeline* mono_pipeline() const { return paths_.mono; }
  // Diagnosis only (bench tools): sees every hypothesis of the following stereo searches.
  void SetSearchObserver(SearchObserver* observer) { paths_.stereo->SetSearchObserver(observer); }
  const ModelSet& models() const { return models_; }

 private:
  // Sets the texture path up for the model set's printed models.
  Status InitPrinted(const StereoCalibration& calib, const ModelSet& models);
  // The monocular fallback's aspect table and its models' stereo ids, set up for the left camera.
  Status InitFallback(const StereoCalibration& calib, const ModelSet& models);
  // The aspect table of the monocular fallback (config_.aspects_file's, else the linked-in one).
  Result<AspectTableView> OpenAspects();
  // Sets the monocular pipeline up for `camera` (0 left, 1 right): no allocation.
  Status InitMono(int camera);
  // Lends the fallback's recogniser (set up for the left camera) to the stereo pipeline's
  // one-image rescue, when its aspect table lists the stereo tables' models in order; after a
  // fallback on the right camera it is set up for the left one again first.
  Status LendRescue();
  // The plane the fallback lays objects onto when no table pose is configured: the stereo
  // frames' carried plane, once confirmed (null: none, free 6-D poses).
  const RigidTransform* CarriedPlaneForMono() const;
  // The printed cartons of the frame (when the mask selects a printed model), the budget they
  // leave to the polyhedral search, and the cartons as objects hidden from it.
  Status RunPrinted(const StereoInput& pair, float budget_ms, float* polyhedra_budget_ms,
                    PosedModel* cartons, size_t* n_cartons);
  // The stereo pipeline's objects, then the printed ones, masked, into out.
  void CollectStereo(bool printed, RecognitionOutput* out) const;
  // The frame's table and its pose (as the stereo pipeline used it).
  void NoteTable(RecognitionOutput* out) const;
  void NoteCarryChange(const TableCarry& carry);
  // Sets rescue_lent_ and says so when that changed.
  void NoteRescueLent(bool lent, const char* why);
  // Counts what the rescue did in the frame just processed.
  void CountRescue(bool lent, const RescueStats& stats);
  // config_.log with a formatted line.
  void Log(const char* fmt, ...) const __attribute__((format(printf, 2, 3)));
  const RigidTransform& LeftTTable() const;
  bool Selected(uint32_t model) const { return model < 32 && (model_mask_ & (1u << model)) != 0; }

  RecognitionPathSet paths_;
  ObjectRecognizerConfig config_;
  ModelSet models_;
  uint32_t model_mask_ = 0;
  bool printed_ = false;      // the model set has printed models and the texture path is set up
  bool printed_ran_ = false;  // ... and it ran on the last stereo frame
  PipelineResult result_;
  bool carry_trusted_ = false;  // the carried plane's state last said
  uint32_t carry_drops_ = 0;
  AspectTableView aspects_;
  MappedAspectTable mapped_aspects_;  // the model set's ASPECTS_2D section, when it has one
  StereoCalibration calib_;
  // Stereo table model id of each aspect table model, by name (-1: not in the stereo tables).
  int table_id_of_aspect_model_[kMaxAspectModels] = {};
  // The carried plane the monocular pipeline was set up with (mono_on_carried_plane_).
  RigidTransform mono_left_T_table_;
  bool mono_on_carried_plane_ = false;
  // The stereo pipeline's rescue runs on the fallback's recogniser; the state last said.
  std::atomic<bool> rescue_lent_{false};
  enum class RescueLog : uint8_t { kNone, kOn, kOff } rescue_logged_ = RescueLog::kNone;
  std::atomic<uint64_t> rescue_lends_{0}, rescue_frames_lent_{0}, rescue_frames_ran_{0},
      rescue_found_{0}, rescue_added_{0};
};

}  // namespace sh
