// Recognition through the recognition pipeline (recog/pipeline): the board's recogniser. With
// a feature database in the model set, the texture path (recog/texture) runs on each frame
// after the polyhedral one, on the pipeline's worker pool, and its printed models follow the
// polyhedra in the result set. With a monocular pipeline (recog/mono) it also recognises from one
// camera when the other has failed.
#pragma once

#include <atomic>
#include <cstdint>

#include "firmware/recognition.hpp"
#include "recog/mono/mono_pipeline.hpp"
#include "recog/pipeline/pipeline.hpp"
#include "recog/texture/texture_recognizer.hpp"
#include "tables/aspect_file.hpp"
#include "tables/aspect_view.hpp"

namespace sh::fw {

struct PipelineRecognitionConfig {
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
  // one image cannot tell depth (kMonoNeedsTablePlane); the sets go out with status 3 and an
  // EMCY.
  bool mono_table_known = false;
  // A model set (the `tables` file) whose ASPECTS_2D section, if it has one, replaces the
  // linked-in aspect table of the monocular fallback; nullptr: the linked-in one.
  const char* aspects_file = nullptr;
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

class PipelineRecognition final : public Recognition {
 public:
  // `pipeline` is large (tens of MiB): the caller keeps it in static storage. `texture` (about
  // 63 MiB) and `texture_result` are needed for printed models only (null: a feature database
  // in the model set fails Init); allocated once at start-up. `mono` (1.0 MiB, allocated
  // once at start-up when the fallback is configured) and `mono_result` are the one-camera
  // fallback (null: none); the monocular pipeline
  // borrows the stereo pipeline's feature workspace of the camera it runs on.
  PipelineRecognition(Pipeline* pipeline, const PipelineRecognitionConfig& config,
                      texture::TextureRecognizer* texture = nullptr,
                      texture::TextureResult* texture_result = nullptr,
                      MonoPipeline* mono = nullptr, MonoResult* mono_result = nullptr)
      : pipeline_(pipeline),
        config_(config),
        texture_(texture),
        texture_result_(texture_result),
        mono_(mono),
        mono_result_(mono_result) {}

  Status Init(const StereoCalibration& calib, const ModelSet& models, uint32_t model_mask) override;
  // The monocular fallback's aspect table (valid after Init).
  const AspectTableView& aspects() const { return aspects_; }
  Status SetModelMask(uint32_t model_mask) override;
  Status Process(const hal::StereoFrame& frame, float budget_ms, protocol::ResultSet* set) override;
  bool monocular() const override { return mono_ != nullptr && mono_->initialised(); }
  // The monocular pipeline lays objects onto the stereo frames' carried plane (no table pose
  // configured; the plane was confirmed before the fallback).
  bool mono_on_carried_plane() const { return mono_on_carried_plane_; }
  Status ProcessMonocular(hal::StereoSide side, ConstGrayView image, float budget_ms,
                          protocol::ResultSet* set) override;
  // The rescue's counters (written by the thread that calls Process, read by any) and whether
  // the fallback's recogniser is lent to it now.
  RescueCounters rescue_counters() const;
  bool rescue_lent() const { return rescue_lent_.load(std::memory_order_relaxed); }

 private:
  // The printed models' objects after the n objects already in *set, masked, up to capacity.
  void AddPrinted(protocol::ResultSet* set, size_t n) const;
  static protocol::TablePlane TablePlaneOf(TableSource source);
  // Logs a table plane confirmed or dropped since the last frame.
  void NoteCarryChange(const TableCarry& carry);
  // Sets the texture path up for the model set's printed models.
  Status InitPrinted(const StereoCalibration& calib, const ModelSet& models);
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
  // Sets rescue_lent_ and logs when that changed.
  void NoteRescueLent(bool lent, const char* why);
  // Counts what the rescue did in the frame just processed.
  void CountRescue(bool lent, const RescueStats& stats);

  Pipeline* pipeline_;
  PipelineRecognitionConfig config_;
  texture::TextureRecognizer* texture_;
  texture::TextureResult* texture_result_;
  ModelSet models_;
  uint32_t model_mask_ = 0;
  bool printed_ = false;  // the model set has printed models and the texture path is set up
  PipelineResult result_;
  bool carry_trusted_ = false;  // the carried plane's state the log last reported
  uint32_t carry_drops_ = 0;
  MonoPipeline* mono_;
  MonoResult* mono_result_;
  AspectTableView aspects_;
  MappedAspectTable mapped_aspects_;  // the model set's ASPECTS_2D section, when it has one
  StereoCalibration calib_;
  // Stereo table model id of each aspect table model, by name (-1: not in the stereo tables).
  int table_id_of_aspect_model_[kMaxAspectModels] = {};
  // The carried plane the monocular pipeline was set up with (mono_on_carried_plane_).
  RigidTransform mono_left_T_table_;
  bool mono_on_carried_plane_ = false;
  // The stereo pipeline's rescue runs on mono_'s recogniser; the state the log last reported.
  std::atomic<bool> rescue_lent_{false};
  enum class RescueLog : uint8_t { kNone, kOn, kOff } rescue_logged_ = RescueLog::kNone;
  std::atomic<uint64_t> rescue_lends_{0}, rescue_frames_lent_{0}, rescue_frames_ran_{0},
      rescue_found_{0}, rescue_added_{0};
};

}  // namespace sh::fw
