#include "recog/pipeline/object_recognizer.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

#include "recog/stereo/working_volume.hpp"

namespace sh {

const char* RecognitionPathName(RecognitionPath path) {
  switch (path) {
    case RecognitionPath::kPolyhedra:
      return "polyhedra";
    case RecognitionPath::kColourParts:
      return "colour parts";
    case RecognitionPath::kPrinted:
      return "printed";
    case RecognitionPath::kOneCamera:
      return "one camera";
  }
  return "?";
}

namespace {

// The caller's tuned configuration, else the automatic default or a preset (detectors,
// verification, search), not bare defaults.
template <typename Config>
Config PresetOf(const ObjectRecognizerConfig& c, const Config* tuned) {
  if (tuned != nullptr) return *tuned;
  return c.automatic          ? Config::Automatic()
         : c.light_background ? Config::LightBackground()
                              : Config::DarkBackground();
}

// The working volume the settings name: a box in the left camera or the table frame, else the
// space over a known table, else none.
void SetWorkingVolume(const ObjectRecognizerConfig& c, const RigidTransform& left_T_table,
                      PipelineConfig* config) {
  if (c.volume_set) {
    const Eigen::Vector3f min_mm(c.volume_min_mm[0], c.volume_min_mm[1], c.volume_min_mm[2]);
    const Eigen::Vector3f max_mm(c.volume_max_mm[0], c.volume_max_mm[1], c.volume_max_mm[2]);
    config->stereo.volume = c.volume_in_table_frame
                                ? WorkingVolume::InFrame(left_T_table, min_mm, max_mm)
                                : WorkingVolume::InLeftCamera(min_mm, max_mm);
  } else if (c.volume_over_table) {
    config->stereo.volume = WorkingVolume::OverTable(left_T_table);
  }
}

}  // namespace

const RigidTransform& ObjectRecognizer::LeftTTable() const {
  return config_.left_T_table_at_init != nullptr ? *config_.left_T_table_at_init
                                                 : config_.left_T_table;
}

void ObjectRecognizer::Log(const char* fmt, ...) const {
  if (config_.log == nullptr) return;
  char line[256];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof(line), fmt, args);
  va_end(args);
  config_.log(line);
}

Status ObjectRecognizer::Init(const StereoCalibration& calib, const ModelSet& models,
                              uint32_t model_mask) {
  if (paths_.stereo == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "no stereo pipeline given");
  }
  models_ = models;
  model_mask_ = model_mask;
  printed_ = false;
  printed_ran_ = false;
  carry_trusted_ = false;  // Init starts the carried plane again
  carry_drops_ = 0;
  rescue_lent_ = false;  // the pipeline's Init takes the rescue's recogniser back
  PipelineConfig config = PresetOf(config_, config_.stereo_preset);
  config.threads = config_.threads;
  config.rgb_frames = config_.rgb_frames;
  if (config_.table_known) {
    config.table.known = true;
    config.table.left_T_table = LeftTTable();
  }
  config.table_estimate.enabled = config_.table_estimate;
  config.table_carry.enabled = config_.table_estimate && config_.table_carry;
  config.table_carry.confirm_frames = config_.table_confirm_frames;
  config.table_carry.check_every_frames = config_.table_check_frames;
  SetWorkingVolume(config_, LeftTTable(), &config);
  config.recognizer.model_mask = model_mask;
  const TableView table = models.hash() != nullptr ? *models.hash() : TableView();
  // The colour parts' view database, when the set has one: the pipeline then allocates the
  // shape path's buffers (here, at boot) and runs it on colour frames.
  SH_RETURN_IF_ERROR(paths_.stereo->Init(calib, table, config, config_.now_ns, models.shape()));
  if (models.printed() != nullptr) SH_RETURN_IF_ERROR(InitPrinted(calib, models));
  if (paths_.mono == nullptr) return Status::Ok();
  SH_RETURN_IF_ERROR(InitFallback(calib, models));
  return LendRescue();
}

Status ObjectRecognizer::InitFallback(const StereoCalibration& calib, const ModelSet& models) {
  // The model set's aspect table, else the linked-in one; its models found in the stereo tables
  // by name (the tables may come from a file with other models), set up for the left camera now
  // so that bad data shows at boot.
  const Result<AspectTableView> aspects = OpenAspects();
  if (!aspects.ok()) {
    return Status::Error(aspects.status().code(), "aspect table: %s", aspects.status().message());
  }
  aspects_ = *aspects;
  for (uint32_t m = 0; m < aspects_.model_count() && m < kMaxAspectModels; ++m) {
    table_id_of_aspect_model_[m] =
        models.hash() != nullptr ? models.hash()->FindModel(aspects_.model(m).name) : -1;
  }
  calib_ = calib;
  return InitMono(0);
}

Status ObjectRecognizer::LendRescue() {
  if (paths_.mono == nullptr || !paths_.stereo->config().rescue.enabled) return Status::Ok();
  if (!paths_.mono->initialised() || paths_.mono->camera() != 0) SH_RETURN_IF_ERROR(InitMono(0));
  // Other models or another order (a model set without its own aspect table): no rescue.
  if (!paths_.stereo->LendRescue(&paths_.mono->recognizer()).ok()) {
    NoteRescueLent(false, "the fallback's aspect table lists other models than the stereo tables");
    return Status::Ok();
  }
  rescue_lends_.fetch_add(1, std::memory_order_relaxed);
  NoteRescueLent(true,
                 "the one-camera fallback's recogniser (left camera) lent to the stereo pipeline");
  return Status::Ok();
}

void ObjectRecognizer::NoteRescueLent(bool lent, const char* why) {
  rescue_lent_.store(lent, std::memory_order_relaxed);
  // Only on a change: a mask change lends it again, an aspect table of other models is tried at
  // each frame.
  const RescueLog state = lent ? RescueLog::kOn : RescueLog::kOff;
  if (state == rescue_logged_) return;
  Log("one-image rescue %s: %s", lent ? "on" : "off", why);
  rescue_logged_ = state;
}

void ObjectRecognizer::CountRescue(bool lent, const RescueStats& stats) {
  if (!lent) return;
  rescue_frames_lent_.fetch_add(1, std::memory_order_relaxed);
  if (stats.ran) rescue_frames_ran_.fetch_add(1, std::memory_order_relaxed);
  rescue_found_.fetch_add(stats.found, std::memory_order_relaxed);
  rescue_added_.fetch_add(stats.added, std::memory_order_relaxed);
}

RescueCounters ObjectRecognizer::rescue_counters() const {
  RescueCounters c;
  c.lends = rescue_lends_.load(std::memory_order_relaxed);
  c.frames_lent = rescue_frames_lent_.load(std::memory_order_relaxed);
  c.frames_ran = rescue_frames_ran_.load(std::memory_order_relaxed);
  c.found = rescue_found_.load(std::memory_order_relaxed);
  c.added = rescue_added_.load(std::memory_order_relaxed);
  return c;
}

bool ObjectRecognizer::monocular() const {
  return paths_.mono != nullptr && paths_.mono->initialised();
}

Result<AspectTableView> ObjectRecognizer::OpenAspects() {
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

Status ObjectRecognizer::InitPrinted(const StereoCalibration& calib, const ModelSet& models) {
  if (paths_.texture == nullptr || paths_.texture_result == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "printed models loaded but no texture recogniser set up");
  }
  texture::TextureRecognizerConfig texture_config;
  // The working volume's depths are not known here: the recogniser's default range of depths
  // (300..900 mm) sets its Hough scales.
  SH_RETURN_IF_ERROR(paths_.texture
                         ->Init(calib, *models.printed(), texture_config, config_.now_ns,
                                texture::ParallelOn(paths_.stereo->pool()))
                         .WithContext("texture path"));
  printed_ = true;
  return Status::Ok();
}

Status ObjectRecognizer::InitMono(int camera) {
  const MonoPipelineConfig config = PresetOf(config_, config_.mono_preset);
  const RigidTransform* left_T_table = nullptr;
  const RigidTransform* carried = CarriedPlaneForMono();
  mono_on_carried_plane_ = false;
  if (config_.mono_table_known) {
    left_T_table = &LeftTTable();
  } else if (carried != nullptr) {
    mono_left_T_table_ = *carried;
    left_T_table = &mono_left_T_table_;
    mono_on_carried_plane_ = true;
  }
  const Status s =
      paths_.mono->Init(calib_, camera, aspects_, left_T_table, config, config_.now_ns);
  if (!s.ok()) return Status::Error(s.code(), "monocular fallback: %s", s.message());
  if (mono_on_carried_plane_) {
    Log("one camera (%s): objects laid onto the carried table plane",
        camera == 0 ? "left" : "right");
  }
  return Status::Ok();
}

const RigidTransform* ObjectRecognizer::CarriedPlaneForMono() const {
  if (config_.mono_table_known || !config_.table_estimate || !config_.table_carry) return nullptr;
  const TableCarry& carry = paths_.stereo->table_carry();
  return carry.trusted() ? &carry.left_T_table() : nullptr;
}

Status ObjectRecognizer::ProcessMonocular(int camera, ConstGrayView image, float budget_ms,
                                          RecognitionOutput* out) {
  if (paths_.mono == nullptr || paths_.mono_result == nullptr) {
    return Status::Error(StatusCode::kFailedPrecondition, "no monocular pipeline");
  }
  out->objects.clear();
  out->one_camera = true;
  out->budget_hit = false;
  out->time = PipelineTimings();
  // Set up again when the camera changed, or when the stereo frames confirmed, moved or dropped
  // the carried plane since: once per fallback, not per frame (the stereo path is idle meanwhile).
  const RigidTransform* carried = CarriedPlaneForMono();
  if (!config_.mono_table_known && carried == nullptr) {
    // No poses rather than guessed ones, every frame until the camera is back or a plane is
    // known.
    return Status::Error(StatusCode::kFailedPrecondition,
                         "%s; set table_file or table_estimate = carry", kMonoNeedsTablePlane);
  }
  const bool plane_changed = (carried != nullptr) != mono_on_carried_plane_ ||
                             (carried != nullptr && (carried->R != mono_left_T_table_.R ||
                                                     carried->t_mm != mono_left_T_table_.t_mm));
  if (!paths_.mono->initialised() || paths_.mono->camera() != camera || plane_changed) {
    SH_RETURN_IF_ERROR(InitMono(camera));
  }
  // Set up for the right camera, it no longer serves the stereo frames' rescue.
  if (rescue_lent_ && camera != 0) {
    (void)paths_.stereo->LendRescue(nullptr);
    NoteRescueLent(false, "the fallback's recogniser serves the right camera");
  }
  // The stereo pipeline is idle while one camera is out: its workspace of that camera is free.
  SH_RETURN_IF_ERROR(
      paths_.mono->Process(image, budget_ms, paths_.stereo->workspace(camera), paths_.mono_result));
  for (const RecognizedObject& o : paths_.mono_result->objects) {
    const int id = o.model < kMaxAspectModels ? table_id_of_aspect_model_[o.model] : -1;
    if (id < 0 || !Selected(static_cast<uint32_t>(id))) continue;
    const float score = std::clamp(o.verify_score[0], 0.0f, 1.0f);  // edge samples confirmed
    (void)out->objects.push_back(
        {o.cam_T_model, static_cast<uint32_t>(id), o.instance, score, RecognitionPath::kOneCamera});
  }
  // A configured pose is the file's; the simulator's rendered table (known to the fallback, not
  // configured) is none.
  out->table_source = mono_on_carried_plane_                            ? TableSource::kCarried
                      : config_.mono_table_known && config_.table_known ? TableSource::kGiven
                                                                        : TableSource::kNone;
  return Status::Ok();
}

Status ObjectRecognizer::SetModelMask(uint32_t model_mask) {
  // Re-initialising with the same calibration and table only reconfigures (no allocation).
  PipelineConfig config = paths_.stereo->config();
  config.recognizer.model_mask = model_mask;
  const StereoCalibration calib = paths_.stereo->calibration();
  const TableView table = paths_.stereo->table();
  // The cameras did not move: the carried table plane stays.
  const TableCarry carry = paths_.stereo->table_carry();
  SH_RETURN_IF_ERROR(paths_.stereo->Init(calib, table, config, config_.now_ns, models_.shape()));
  paths_.stereo->RestoreTableCarry(carry);
  rescue_lent_ = false;  // Init took it back (lent again at once: nothing to say)
  SH_RETURN_IF_ERROR(LendRescue());
  model_mask_ = model_mask;  // the colour and printed models' bits are applied to their objects
  return Status::Ok();
}

Status ObjectRecognizer::RunPrinted(const StereoInput& pair, float budget_ms,
                                    float* polyhedra_budget_ms, PosedModel* cartons,
                                    size_t* n_cartons) {
  const int64_t start_ns = config_.now_ns != nullptr ? config_.now_ns() : 0;
  SH_RETURN_IF_ERROR(
      paths_.texture->Process(pair.left_grey, pair.right_grey, paths_.texture_result));
  if (config_.now_ns != nullptr && budget_ms > 0) {
    // Nanoseconds to milliseconds. At least 1 ms remains: a budget <= 0 would mean no limit.
    const float spent_ms = static_cast<float>(config_.now_ns() - start_ns) * 1e-6f;
    *polyhedra_budget_ms = std::max(budget_ms - spent_ms, 1.0f);
  }
  // The cartons found are hidden from the polyhedral path: their box edges, corners and the
  // print's straight lines would otherwise fill its features and its search, and a polyhedron
  // inside a carton (its box edges read as a polyhedron) is not reported.
  for (const texture::TextureObject& c : paths_.texture_result->objects) {
    if (*n_cartons == kMaxRecognitionCartons) break;
    cartons[(*n_cartons)++] = {&paths_.texture->db().model(c.model), c.cam_T_model};
  }
  return Status::Ok();
}

Status ObjectRecognizer::Process(const StereoInput& pair, float budget_ms, RecognitionOutput* out) {
  out->objects.clear();
  out->one_camera = false;
  // The printed models first, when the mask selects one: the texture path is bounded and not
  // interruptible, the polyhedral search is the anytime part and gets what is left of the budget.
  const uint32_t printed_bits = models_.printed_count() >= 32
                                    ? ~0u
                                    : ((1u << models_.printed_count()) - 1u)
                                          << models_.printed_offset();
  const bool printed = printed_ && (model_mask_ & printed_bits) != 0;
  printed_ran_ = printed;
  float polyhedra_budget_ms = budget_ms;
  PosedModel cartons[kMaxRecognitionCartons];
  size_t n_cartons = 0;
  if (printed) {
    SH_RETURN_IF_ERROR(RunPrinted(pair, budget_ms, &polyhedra_budget_ms, cartons, &n_cartons));
  }
  // Back from a fallback on the right camera: the rescue's recogniser for the left one again.
  if (!rescue_lent_) SH_RETURN_IF_ERROR(LendRescue());
  // The frames as delivered: the polyhedral path reads their grey (the Y plane in place), the
  // colour parts' path runs when they are colour and the set holds colour parts.
  SH_RETURN_IF_ERROR(paths_.stereo->Process(pair.left, pair.right, polyhedra_budget_ms, &result_,
                                            cartons, n_cartons));
  CountRescue(rescue_lent_, result_.rescue);
  out->budget_hit = result_.recognition.budget_exhausted;
  out->time = result_.time;
  NoteTable(out);
  NoteCarryChange(result_.table_carry);
  CollectStereo(printed, out);
  return Status::Ok();
}

void ObjectRecognizer::NoteTable(RecognitionOutput* out) const {
  out->table_source = result_.table_source;
  if (result_.table_source == TableSource::kGiven) {
    out->left_T_table = LeftTTable();
  } else if (result_.table_source == TableSource::kEstimated) {
    out->left_T_table = result_.table_estimate.left_T_table;
  } else if (result_.table_source == TableSource::kCarried) {
    out->left_T_table = result_.table_carry.left_T_table();
  }
}

void ObjectRecognizer::CollectStereo(bool printed, RecognitionOutput* out) const {
  for (const RecognizedObject& o : result_.objects) {
    // The mask selects colour parts too (the polyhedral search applies it itself).
    if (!Selected(o.model)) continue;
    // The weaker image decides: an object must be confirmed in both views.
    const float score = std::clamp(std::min(o.verify_score[0], o.verify_score[1]), 0.0f, 1.0f);
    const RecognitionPath path =
        models_.is_shape(o.model) ? RecognitionPath::kColourParts : RecognitionPath::kPolyhedra;
    (void)out->objects.push_back({o.cam_T_model, o.model, o.instance, score, path});
  }
  if (!printed) return;
  uint32_t instances[kMaxRecognitionCartons] = {};
  for (const texture::TextureObject& o : paths_.texture_result->objects) {
    const uint32_t id = models_.printed_offset() + o.model;
    if (!Selected(id)) continue;
    // Print correlation (ZNCC) of the weaker image, as the polyhedra's verification score.
    const float score = std::clamp(std::min(o.print.zncc[0], o.print.zncc[1]), 0.0f, 1.0f);
    const uint32_t instance = o.model < kMaxRecognitionCartons ? instances[o.model]++ : 0;
    // Full (every stereo object and carton fit): nothing is dropped here.
    (void)out->objects.push_back({o.cam_T_model, id, instance, score, RecognitionPath::kPrinted});
  }
}

void ObjectRecognizer::NoteCarryChange(const TableCarry& carry) {
  const bool trusted = carry.trusted();
  if (trusted == carry_trusted_ && carry.drops() == carry_drops_) return;
  // The integrator's view of the cell: when the plane is confirmed, and when it is dropped (the
  // table moved, or the estimate was wrong). Only on a change: no output per frame.
  const Eigen::Vector3f up = carry.left_T_table().R.col(2);
  if (carry.drops() != carry_drops_) {
    Log("table plane dropped (%u so far): estimating again", carry.drops());
  }
  if (trusted) {
    Log("table plane confirmed by %u frames and carried: normal (%.4f, %.4f, %.4f), the left "
        "camera %.1f mm over it",
        carry.agreeing(), double(up.x()), double(up.y()), double(up.z()),
        double(up.dot(carry.left_T_table().t_mm)) * -1.0);
  }
  carry_trusted_ = trusted;
  carry_drops_ = carry.drops();
}

}  // namespace sh
