#include "firmware/web/status_json.hpp"

#include <utility>

#include "firmware/web/json_writer.hpp"

namespace sh::fw::web {
namespace {

void WriteLines(const std::vector<std::vector<float>>& lines, JsonWriter* j) {
  j->BeginArray();
  for (const auto& line : lines) {
    j->BeginArray();
    for (float v : line) j->Number(v, 5);
    j->EndArray();
  }
  j->EndArray();
}

const char* StateName(FirmwareState s) {
  switch (s) {
    case FirmwareState::kInit:
      return "init";
    case FirmwareState::kReady:
      return "ready";
    case FirmwareState::kBusy:
      return "busy";
    case FirmwareState::kFault:
      return "fault";
  }
  return "?";
}

const char* ResultStatusText(protocol::ResultStatus s) {
  switch (s) {
    case protocol::ResultStatus::kOk:
      return "ok";
    case protocol::ResultStatus::kTimeBudgetHit:
      return "time budget hit";
    case protocol::ResultStatus::kImageError:
      return "image error";
    case protocol::ResultStatus::kInternalError:
      return "internal error";
    case protocol::ResultStatus::kMonocular:
      return "one camera";
  }
  return "?";
}

void WriteHealth(const WebHealth& h, JsonWriter* j) {
  j->Key("state").String(StateName(h.state)).Key("nmt").String(protocol::NmtStateName(h.nmt));
  j->Key("node_id").Int(h.node_id).Key("fault_bits").Uint(h.fault_bits);
  j->Key("error_register").Uint(h.error_register).Key("heartbeat_ms").Uint(h.heartbeat_ms);
  j->Key("budget_ms").Uint(h.budget_ms).Key("free_run_dhz").Uint(h.free_run_dhz);
  j->Key("model_mask").Uint(h.model_mask);
  j->Key("capture_mode").String(hal::CaptureModeName(h.capture_mode));
  const CoreCounters& c = h.counters;
  j->Key("counters").BeginObject();
  j->Key("triggers_accepted")
      .Uint(c.triggers_accepted)
      .Key("triggers_rejected")
      .Uint(c.triggers_rejected);
  j->Key("triggers_dropped").Uint(c.triggers_dropped).Key("result_sets").Uint(c.result_sets);
  j->Key("capture_errors")
      .Uint(c.capture_errors)
      .Key("recognition_errors")
      .Uint(c.recognition_errors);
  j->Key("emcy_sent").Uint(c.emcy_sent).Key("heartbeats").Uint(c.heartbeats);
  j->Key("send_errors").Uint(c.send_errors).EndObject();
  const hal::CameraStats& cam = h.camera;
  j->Key("camera").BeginObject();
  j->Key("pairs_delivered").Uint(cam.pairs_delivered).Key("timeouts").Uint(cam.timeouts);
  j->Key("unpaired_drops").Uint(cam.left_unpaired_drops + cam.right_unpaired_drops);
  j->Key("overflow_drops")
      .Uint(cam.left_overflow_drops + cam.right_overflow_drops + cam.pair_overflow_drops);
  j->Key("errors").Uint(cam.errors).EndObject();
  j->Key("can").BeginObject().Key("state").String(hal::CanBusStateName(h.can_state));
  j->Key("tx_frames").Uint(h.can.tx_frames).Key("rx_frames").Uint(h.can.rx_frames);
  j->Key("tx_dropped").Uint(h.can.tx_dropped_queue_full);
  j->Key("rx_dropped").Uint(h.can.rx_dropped_overflow);
  j->Key("bus_off_events").Uint(h.can.bus_off_events).Key("error_frames").Uint(h.can.error_frames);
  j->EndObject();
  j->Key("emcy_history").BeginArray();
  for (size_t i = 0; i < h.emcy_count; ++i) {
    const uint16_t code = static_cast<uint16_t>(h.emcy_history[i] & 0xFFFF);
    j->BeginObject().Key("code").Uint(code).Key("detail").Uint(h.emcy_history[i] >> 16);
    j->Key("text").String(EmcyCodeText(code)).EndObject();
  }
  j->EndArray();
  j->Key("recording").BeginObject().Key("on").Bool(h.recording);
  j->Key("pending").Int(h.record_pending).Key("written").Uint(h.recorder.written);
  j->Key("dropped").Uint(h.recorder.dropped).Key("failed").Uint(h.recorder.failed).EndObject();
}

void WriteResult(const LiveResult& r, const std::vector<OverlayObject>& overlay,
                 const char* output_frame, int64_t now_ns, JsonWriter* j) {
  j->Key("result").BeginObject().Key("count").Uint(r.results);
  j->Key("age_ms").Int(r.results ? (now_ns - r.published_ns) / 1'000'000 : -1);
  j->Key("sequence").Uint(r.set.sequence).Key("status").String(ResultStatusText(r.set.status));
  j->Key("latency_us").Uint(r.set.processing_time_us).Key("output_frame").String(output_frame);
  j->Key("table").String(protocol::TablePlaneName(r.set.table)).Key("has_images").Bool(r.has_frame);
  const protocol::StageTimes& st = r.set.stages;
  j->Key("stages_ms").BeginObject().Key("features").Number(st.features_ms, 4);
  j->Key("stereo").Number(st.stereo_ms, 4).Key("hashing").Number(st.hashing_ms, 4);
  j->Key("verify").Number(st.verify_ms, 4).Key("refine").Number(st.refine_ms, 4);
  j->Key("total").Number(st.total_ms, 4).EndObject();
  j->Key("image_size").BeginArray();
  for (int side = 0; side < 2; ++side) {
    j->BeginArray().Int(r.full_width[side]).Int(r.full_height[side]).EndArray();
  }
  j->EndArray().Key("objects").BeginArray();
  for (size_t i = 0; i < overlay.size() && i < r.set.object_count; ++i) {
    const protocol::ObjectPose& p = r.set.objects[i];
    const OverlayObject& o = overlay[i];
    j->BeginObject().Key("model_id").Int(p.model_id).Key("name").String(o.name.c_str());
    j->Key("instance").Int(p.instance).Key("score").Number(p.score, 4);
    j->Key("t_mm").BeginArray();
    for (double t : p.cam_t_model_mm) j->Number(t, 7);
    j->EndArray().Key("q_wxyz").BeginArray();
    for (double q : p.cam_q_model) j->Number(q, 6);
    j->EndArray().Key("lines").BeginArray();
    for (const auto& side : o.lines) WriteLines(side, j);
    j->EndArray().EndObject();
  }
  j->EndArray().EndObject();
}

}  // namespace

const char* EmcyCodeText(uint16_t code) {
  switch (static_cast<protocol::EmcyCode>(code)) {
    case protocol::EmcyCode::kNoError:
      return "error reset";
    case protocol::EmcyCode::kGeneric:
      return "generic error";
    case protocol::EmcyCode::kDeviceHardware:
      return "board hardware (GPIO, memory)";
    case protocol::EmcyCode::kSoftware:
      return "internal software error";
    case protocol::EmcyCode::kDataSet:
      return "model data or cell geometry missing or corrupt";
    case protocol::EmcyCode::kSensor:
      return "camera: no frames, timeout, pairing lost or one camera";
    case protocol::EmcyCode::kCommunication:
      return "CAN communication";
    case protocol::EmcyCode::kCanOverrun:
      return "CAN: received frames lost";
    case protocol::EmcyCode::kCanErrorPassive:
      return "CAN: error passive";
    case protocol::EmcyCode::kRecoveredFromBusOff:
      return "CAN: recovered from bus-off";
    case protocol::EmcyCode::kProtocolError:
      return "command rejected";
    case protocol::EmcyCode::kPdoLengthError:
      return "command frame too short";
    case protocol::EmcyCode::kRecording:
      return "a recorded pair could not be written";
  }
  return "unknown error code";
}

std::string StatusJson(const WebHealth& health, const LiveResult& result,
                       const StatusOverlay& overlay, const char* output_frame, int64_t now_ns,
                       const StatusAccess& access) {
  JsonWriter j;
  j.BeginObject();
  j.Key("access").BeginObject().Key("login_possible").Bool(access.login_possible);
  j.Key("logged_in").Bool(access.logged_in).Key("csrf").String(access.csrf.c_str()).EndObject();
  j.Key("health").BeginObject();
  WriteHealth(health, &j);
  j.EndObject();
  WriteResult(result, *overlay.objects, output_frame, now_ns, &j);
  for (const auto& [key, lines] :
       {std::pair<const char*, const ImageLines*>{"volume", overlay.volume},
        {"table_plane", overlay.table}}) {
    j.Key(key);
    if (lines == nullptr) {
      j.Null();
      continue;
    }
    j.BeginArray();
    WriteLines(lines[0], &j);
    WriteLines(lines[1], &j);
    j.EndArray();
  }
  j.EndObject();
  return j.text();
}

}  // namespace sh::fw::web
