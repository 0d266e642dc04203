#include "firmware/pipeline_recognition.hpp"

#include <algorithm>
#include <cstdio>

#include "firmware/firmware_core.hpp"
#include "tables/aspect_file.hpp"

namespace sh::fw {

Status PipelineRecognition::Init(const StereoCalibration& calib, const ModelSet& models,
                                 uint32_t model_mask) {
  models_ = models;
  model_mask_ = model_mask;
  printed_ = false;
  carry_trusted_ = false;  // Init starts the carried plane again
  carry_drops_ = 0;
  rescue_lent_ = false;  // the pipeline's Init takes the rescue's recogniser back
  // The automatic default or a preset (detectors, verification, search), not bare defaults.
  PipelineConfig config = config_.automatic          ? PipelineConfig::Automatic()
                          : config_.light_background ? PipelineConfig::LightBackground()
                                                     : PipelineConfig::DarkBackground();
  config.threads = config_.threads;
  config.rgb_frames = config_.rgb_frames;
  const RigidTransform& left_T_table = config_.left_T_table_at_init != nullptr
                                           ? *config_.left_T_table_at_init
                                           : config_.left_T_table;
  if (config_.table_known) {
    config.table.known = true;
    config.table.left_T_table = left_T_table;
  }
  config.table_estimate.enabled = config_.table_estimate;
  config.table_carry.enabled = config_.table_estimate && config_.table_carry;
  config.table_carry.confirm_frames = config_.table_confirm_frames;
  config.table_carry.check_every_frames = config_.table_check_frames;
  if (config_.volume_set) {
    const Eigen::Vector3f min_mm(config_.volume_min_mm[0], config_.volume_min_mm[1],
                                 config_.volume_min_mm[2]);
    const Eigen::Vector3f max_mm(config_.volume_max_mm[0], config_.volume_max_mm[1],
                                 config_.volume_max_mm[2]);
    config.stereo.volume = config_.volume_in_table_frame
                               ? WorkingVolume::InFrame(left_T_table, min_mm, max_mm)
                               : WorkingVolume::InLeftCamera(min_mm, max_mm);
  } else if (config_.volume_over_table) {
    config.stereo.volume = WorkingVolume::OverTable(left_T_table);
  }
  config.recognizer.model_mask = model_mask;
  const TableView table = models.hash() != nullptr ? *models.hash() : TableView();
  // The colour parts' view database, when the set has one: the pipeline then allocates the
  // shape path's buffers (here, at boot) and runs it on colour frames.
  SH_RETURN_IF_ERROR(pipeline_->Init(calib, table, config, &MonotonicNs, models.shape()));
  if (models.printed() != nullptr) SH_RETURN_IF_ERROR(InitPrinted(calib, models));
  if (mono_ == nullptr) return Status::Ok();
  // The monocular fallback: the model set's aspect table, else the linked-in one; its models
  // found in the stereo tables by name (the tables may come from a file with other models), set
  // up for the left camera now so that bad data shows at boot.
  const Result<AspectTableView> aspects = OpenAspects();
  if (!aspects.ok()) {
    return Status::Error(aspects.status().code(), "aspect table: %s", aspects.status().message());
  }
  aspects_ = *aspects;
  for (uint32_t m = 0; m < aspects_.model_count() && m < kMaxAspectModels; ++m) {
    table_id_of_aspect_model_[m] =
        models.hash() != nullptr ? table.FindModel(aspects_.model(m).name) : -1;
  }
  calib_ = calib;
  SH_RETURN_IF_ERROR(InitMono(0));
  return LendRescue();
}

Status PipelineRecognition::LendRescue() {
  if (mono_ == nullptr || !pipeline_->config().rescue.enabled) return Status::Ok();
  if (!mono_->initialised() || mono_->camera() != 0) SH_RETURN_IF_ERROR(InitMono(0));
  // Other models or another order (a model set without its own aspect table): no rescue.
  if (!pipeline_->LendRescue(&mono_->recognizer()).ok()) {
    NoteRescueLent(false, "the fallback's aspect table lists other models than the stereo tables");
    return Status::Ok();
  }
  rescue_lends_.fetch_add(1, std::memory_order_relaxed);
  NoteRescueLent(true,
                 "the one-camera fallback's recogniser (left camera) lent to the stereo pipeline");
  return Status::Ok();
}

void PipelineRecognition::NoteRescueLent(bool lent, const char* why) {
  rescue_lent_.store(lent, std::memory_order_relaxed);
  // Only on a change: a mask change lends it again, an aspect table of other models is tried at
  // each frame.
  const RescueLog state = lent ? RescueLog::kOn : RescueLog::kOff;
  if (state == rescue_logged_) return;
  std::fprintf(stderr, "stereohash-fw: one-image rescue %s: %s\n", lent ? "on" : "off", why);
  rescue_logged_ = state;
}

void PipelineRecognition::CountRescue(bool lent, const RescueStats& stats) {
  if (!lent) return;
  rescue_frames_lent_.fetch_add(1, std::memory_order_relaxed);
  if (stats.ran) rescue_frames_ran_.fetch_add(1, std::memory_order_relaxed);
  rescue_found_.fetch_add(stats.found, std::memory_order_relaxed);
  rescue_added_.fetch_add(stats.added, std::memory_order_relaxed);
}

RescueCounters PipelineRecognition::rescue_counters() const {
  RescueCounters c;
  c.lends = rescue_lends_.load(std::memory_order_relaxed);
  c.frames_lent = rescue_frames_lent_.load(std::memory_order_relaxed);
  c.frames_ran = rescue_frames_ran_.load(std::memory_order_relaxed);
  c.found = rescue_found_.load(std::memory_order_relaxed);
  c.added = rescue_added_.load(std::memory_order_relaxed);
  return c;
}

Result<AspectTableView> PipelineRecognition::OpenAspects() {
  // The previous view may point into the mapping about to be replaced.
  aspects_ = AspectTableView();
  mapped_aspects_.Close();
  if (config_.aspects_file != nullptr) {
    const Result<uint32_t> kinds = FileBlobKinds(config_.aspects_file);
    if (kinds.ok() && (*kinds & KindBit(SectionKind::kAspects2d)) != 0) {
      SH_RETURN_IF_ERROR(mapped_aspects_.Open(config_.aspects_file));
      return mapped_aspects_.view();
    }
  }
  return OpenDefaultAspectTable();
}

Status PipelineRecognition::InitPrinted(const StereoCalibration& calib, const ModelSet& models) {
  if (texture_ == nullptr || texture_result_ == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "printed models loaded but no texture recogniser set up");
  }
  texture::TextureRecognizerConfig texture_config;
  // The working volume's depths are not known here: the recogniser's default range of depths
  // (300..900 mm) sets its Hough scales.
  SH_RETURN_IF_ERROR(texture_
                         ->Init(calib, *models.printed(), texture_config, &MonotonicNs,
                                texture::ParallelOn(pipeline_->pool()))
                         .WithContext("texture path"));
  printed_ = true;
  return Status::Ok();
}

Status PipelineRecognition::InitMono(int camera) {
  MonoPipelineConfig config = config_.automatic          ? MonoPipelineConfig::Automatic()
                              : config_.light_background ? MonoPipelineConfig::LightBackground()
                                                         : MonoPipelineConfig::DarkBackground();
  const RigidTransform* left_T_table = nullptr;
  const RigidTransform* carried = CarriedPlaneForMono();
  mono_on_carried_plane_ = false;
  if (config_.mono_table_known) {
    left_T_table = config_.left_T_table_at_init != nullptr ? config_.left_T_table_at_init
                                                           : &config_.left_T_table;
  } else if (carried != nullptr) {
    mono_left_T_table_ = *carried;
    left_T_table = &mono_left_T_table_;
    mono_on_carried_plane_ = true;
  }
  const Status s = mono_->Init(calib_, camera, aspects_, left_T_table, config, &MonotonicNs);
  if (!s.ok()) return Status::Error(s.code(), "monocular fallback: %s", s.message());
  if (mono_on_carried_plane_) {
    std::fprintf(stderr,
                 "stereohash-fw: one camera (%s): objects laid onto the carried table plane\n",
                 camera == 0 ? "left" : "right");
  }
  return Status::Ok();
}

const RigidTransform* PipelineRecognition::CarriedPlaneForMono() const {
  if (config_.mono_table_known || !config_.table_estimate || !config_.table_carry) return nullptr;
  const TableCarry& carry = pipeline_->table_carry();
  return carry.trusted() ? &carry.left_T_table() : nullptr;
}

Status PipelineRecognition::ProcessMonocular(hal::StereoSide side, ConstGrayView image,
                                             float budget_ms, protocol::ResultSet* set) {
  if (mono_ == nullptr || mono_result_ == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "no monocular pipeline");
  }
  const int camera = side == hal::StereoSide::kLeft ? 0 : 1;
  // Set up again when the camera changed, or when the stereo frames confirmed, moved or dropped
  // the carried plane since: once per fallback, not per frame (the stereo path is idle meanwhile).
  const RigidTransform* carried = CarriedPlaneForMono();
  if (!config_.mono_table_known && carried == nullptr) {
    // No poses rather than guessed ones: the result set goes out empty with status 3 and an
    // EMCY, every frame until the camera is back or a plane is known.
    return Status::Error(StatusCode::kFailedPrecondition,
                         "%s; set table_file or table_estimate = carry", kMonoNeedsTablePlane);
  }
  const bool plane_changed = (carried != nullptr) != mono_on_carried_plane_ ||
                             (carried != nullptr && (carried->R != mono_left_T_table_.R ||
                                                     carried->t_mm != mono_left_T_table_.t_mm));
  if (!mono_->initialised() || mono_->camera() != camera || plane_changed) {
    SH_RETURN_IF_ERROR(InitMono(camera));
  }
  // Set up for the right camera, it no longer serves the stereo frames' rescue.
  if (rescue_lent_ && camera != 0) {
    (void)pipeline_->LendRescue(nullptr);
    NoteRescueLent(false, "the fallback's recogniser serves the right camera");
  }
  // The stereo pipeline is idle while one camera is out: its workspace of that camera is free.
  SH_RETURN_IF_ERROR(mono_->Process(image, budget_ms, pipeline_->workspace(camera), mono_result_));
  size_t n = 0;
  for (const RecognizedObject& o : mono_result_->objects) {
    if (n == protocol::kMaxResultObjects) break;
    const int id = o.model < kMaxAspectModels ? table_id_of_aspect_model_[o.model] : -1;
    if (id < 0 || id > 31 || (model_mask_ & (1u << id)) == 0) continue;
    const float score = std::clamp(o.verify_score[0], 0.0f, 1.0f);  // edge samples confirmed
    set->objects[n++] = protocol::MakeObjectPose(o.cam_T_model, static_cast<uint8_t>(id),
                                                 static_cast<uint8_t>(o.instance), score);
  }
  set->object_count = static_cast<uint8_t>(n);
  // As the stereo sets say it: a configured pose is the file's; the simulator's rendered table
  // (known to the fallback, not configured) is none.
  set->table = mono_on_carried_plane_                            ? protocol::TablePlane::kCarried
               : config_.mono_table_known && config_.table_known ? protocol::TablePlane::kFile
                                                                 : protocol::TablePlane::kNone;
  return Status::Ok();
}

Status PipelineRecognition::SetModelMask(uint32_t model_mask) {
  // Re-initialising with the same calibration and table only reconfigures (no allocation).
  PipelineConfig config = pipeline_->config();
  config.recognizer.model_mask = model_mask;
  const StereoCalibration calib = pipeline_->calibration();
  const TableView table = pipeline_->table();
  // The cameras did not move: the carried table plane stays.
  const TableCarry carry = pipeline_->table_carry();
  SH_RETURN_IF_ERROR(pipeline_->Init(calib, table, config, &MonotonicNs, models_.shape()));
  pipeline_->RestoreTableCarry(carry);
  rescue_lent_ = false;  // Init took it back (lent again at once: nothing to log)
  SH_RETURN_IF_ERROR(LendRescue());
  model_mask_ = model_mask;  // the colour and printed models' bits are applied to their objects
  return Status::Ok();
}

void PipelineRecognition::AddPrinted(protocol::ResultSet* set, size_t n) const {
  uint8_t instances[protocol::kMaxResultObjects] = {};
  for (const texture::TextureObject& o : texture_result_->objects) {
    const uint32_t id = models_.printed_offset() + o.model;
    if (id > 31 || !(model_mask_ & (1u << id))) continue;
    if (n == protocol::kMaxResultObjects) break;  // capacity: the rest is not reported
    // Print correlation (ZNCC) of the weaker image, as the polyhedra's verification score.
    const float score = std::clamp(std::min(o.print.zncc[0], o.print.zncc[1]), 0.0f, 1.0f);
    set->objects[n++] = protocol::MakeObjectPose(o.cam_T_model, static_cast<uint8_t>(id),
                                                 instances[o.model]++, score);
  }
  set->object_count = static_cast<uint8_t>(n);
}

Status PipelineRecognition::Process(const hal::StereoFrame& frame, float budget_ms,
                                    protocol::ResultSet* set) {
  // The printed models first, when the mask selects one: the texture path is bounded and not
  // interruptible, the polyhedral search is the anytime part and gets what is left of the budget.
  const uint32_t printed_bits = models_.printed_count() >= 32
                                    ? ~0u
                                    : ((1u << models_.printed_count()) - 1u)
                                          << models_.printed_offset();
  const bool printed = printed_ && (model_mask_ & printed_bits) != 0;
  float polyhedra_budget_ms = budget_ms;
  if (printed) {
    const int64_t start_ns = MonotonicNs();
    SH_RETURN_IF_ERROR(texture_->Process(frame.left, frame.right, texture_result_));
    // Nanoseconds to milliseconds. At least 1 ms remains: a budget <= 0 would mean no limit.
    const float spent_ms = static_cast<float>(MonotonicNs() - start_ns) * 1e-6f;
    if (budget_ms > 0) polyhedra_budget_ms = std::max(budget_ms - spent_ms, 1.0f);
  }
  // The cartons found are hidden from the polyhedral path: their box edges, corners and the
  // print's straight lines would otherwise fill its features and its search, and a polyhedron
  // inside a carton (its box edges read as a polyhedron) is not reported.
  PosedModel cartons[texture::kMaxTextureObjects];
  size_t n_cartons = 0;
  if (printed) {
    for (const texture::TextureObject& c : texture_result_->objects) {
      if (n_cartons == texture::kMaxTextureObjects) break;
      cartons[n_cartons++] = {&texture_->db().model(c.model), c.cam_T_model};
    }
  }
  // Back from a fallback on the right camera: the rescue's recogniser for the left one again.
  if (!rescue_lent_) SH_RETURN_IF_ERROR(LendRescue());
  // The frames as delivered: the polyhedral path reads their grey (the Y plane in place), the
  // colour parts' path runs when they are colour and the set holds colour parts.
  SH_RETURN_IF_ERROR(pipeline_->Process(frame.left_frame, frame.right_frame, polyhedra_budget_ms,
                                        &result_, cartons, n_cartons));
  CountRescue(rescue_lent_, result_.rescue);
  set->status = result_.recognition.budget_exhausted ? protocol::ResultStatus::kTimeBudgetHit
                                                     : protocol::ResultStatus::kOk;
  set->table = TablePlaneOf(result_.table_source);
  if (result_.table_source == TableSource::kGiven) {
    set->left_T_table = config_.left_T_table_at_init != nullptr ? *config_.left_T_table_at_init
                                                                : config_.left_T_table;
  } else if (result_.table_source == TableSource::kEstimated) {
    set->left_T_table = result_.table_estimate.left_T_table;
  } else if (result_.table_source == TableSource::kCarried) {
    set->left_T_table = result_.table_carry.left_T_table();
  }
  const PipelineTimings& t = result_.time;
  set->stages = {t.features_ms, t.stereo_ms, t.hashing_ms, t.verify_ms, t.refine_ms, t.total_ms};
  NoteCarryChange(result_.table_carry);
  size_t n = 0;
  for (const RecognizedObject& o : result_.objects) {
    if (n == protocol::kMaxResultObjects) break;
    // The mask selects colour parts too (the polyhedral search applies it itself).
    if (o.model > 31 || (model_mask_ & (1u << o.model)) == 0) continue;
    // The weaker image decides: an object must be confirmed in both views.
    const float score = std::clamp(std::min(o.verify_score[0], o.verify_score[1]), 0.0f, 1.0f);
    set->objects[n++] = protocol::MakeObjectPose(o.cam_T_model, static_cast<uint8_t>(o.model),
                                                 static_cast<uint8_t>(o.instance), score);
  }
  set->object_count = static_cast<uint8_t>(n);
  if (printed) AddPrinted(set, n);
  return Status::Ok();
}

protocol::TablePlane PipelineRecognition::TablePlaneOf(TableSource source) {
  switch (source) {
    case TableSource::kNone:
      return protocol::TablePlane::kNone;
    case TableSource::kGiven:
      return protocol::TablePlane::kFile;
    case TableSource::kEstimated:
      return protocol::TablePlane::kEstimated;
    case TableSource::kCarried:
      return protocol::TablePlane::kCarried;
  }
  return protocol::TablePlane::kNone;
}

void PipelineRecognition::NoteCarryChange(const TableCarry& carry) {
  const bool trusted = carry.trusted();
  if (trusted != carry_trusted_ || carry.drops() != carry_drops_) {
    // The integrator's view of the cell: when the plane is confirmed, and when it is dropped
    // (the table moved, or the estimate was wrong). Only on a change: no output per frame.
    const Eigen::Vector3f up = carry.left_T_table().R.col(2);
    if (carry.drops() != carry_drops_) {
      std::fprintf(stderr, "stereohash-fw: table plane dropped (%u so far): estimating again\n",
                   carry.drops());
    }
    if (trusted) {
      std::fprintf(stderr,
                   "stereohash-fw: table plane confirmed by %u frames and carried: normal "
                   "(%.4f, %.4f, %.4f), the left camera %.1f mm over it\n",
                   carry.agreeing(), double(up.x()), double(up.y()), double(up.z()),
                   double(up.dot(carry.left_T_table().t_mm)) * -1.0);
    }
    carry_trusted_ = trusted;
    carry_drops_ = carry.drops();
  }
}

}  // namespace sh::fw
