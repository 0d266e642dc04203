#include "firmware/demo_client.hpp"

#include <cmath>
#include <cstdio>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/canopen/emcy.hpp"
#include "firmware/canopen/nmt.hpp"
#include "firmware/plc/result_assembler.hpp"
#include "firmware/result_codec.hpp"

namespace sh::fw {

using namespace sh::protocol;

Status DemoClient::Start(hal::SimCanBus* bus, uint8_t node_id, const char* const* names,
                         int n_names) {
  node_ = node_id;
  names_ = names;
  n_names_ = n_names;
  hal::SimCanEndpointConfig config;
  config.name = "plc";
  const uint32_t ids[] = {kCobEmcy,      kCobResultHeader, kCobResultObject,
                          kCobResultEnd, kCobCommandAck,   kCobHeartbeat};
  for (uint32_t id : ids) config.filter_ids[config.filter_count++] = id + node_id;
  Result<hal::SimCanEndpoint*> ep = bus->AddEndpoint(config);
  if (!ep.ok()) return ep.status();
  endpoint_ = *ep;
  stop_ = false;
  thread_ = std::thread([this] { Run(); });
  return Status::Ok();
}

void DemoClient::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void DemoClient::Run() {
  ResultAssembler assembler(node_);
  bool heartbeat_seen = false;
  while (!stop_.load()) {
    hal::CanFrame frame;
    const Result<bool> got = endpoint_->Receive(&frame, 100);
    if (!got.ok() || !*got) continue;
    if (frame.id == kCobHeartbeat + node_) {
      const Result<NmtState> s = DecodeHeartbeat(frame, node_);
      if (frame.len == 1 && frame.data[0] == 0) {
        std::printf("[plc] boot-up of node %u\n", node_);
      } else if (s.ok() && !heartbeat_seen) {
        heartbeat_seen = true;
        std::printf("[plc] heartbeat: %s\n", NmtStateName(*s));
      }
      std::fflush(stdout);
      continue;
    }
    if (frame.id == kCobEmcy + node_) {
      const Result<Emcy> e = DecodeEmcy(frame, node_);
      if (e.ok()) {
        std::printf("[plc] EMCY 0x%04X register 0x%02X state %u detail 0x%08X\n", e->error_code,
                    e->error_register, static_cast<unsigned>(e->state), e->detail);
      }
      std::fflush(stdout);
      continue;
    }
    const Result<bool> done = assembler.Feed(frame);
    if (!done.ok()) {
      std::printf("[plc] result set dropped: %s\n", done.status().message());
      continue;
    }
    if (!*done) continue;
    const ResultSet& set = assembler.set();
    std::printf("[plc] set %u: %u object(s), status %u, %.1f ms\n", set.sequence, set.object_count,
                static_cast<unsigned>(set.status), set.processing_time_us / 1000.0);
    for (int i = 0; i < set.object_count; ++i) {
      const ObjectPose& p = set.objects[i];
      const char* name = p.model_id < n_names_ && names_ ? names_[p.model_id] : "?";
      std::printf(
          "[plc]   %-10s #%u  t = (%8.2f, %8.2f, %8.2f) mm  q = (%.4f, %.4f, %.4f, %.4f)  "
          "score %.3f\n",
          name, p.instance, p.cam_t_model_mm[0], p.cam_t_model_mm[1], p.cam_t_model_mm[2],
          p.cam_q_model[0], p.cam_q_model[1], p.cam_q_model[2], p.cam_q_model[3], p.score);
    }
    std::fflush(stdout);
  }
}

}  // namespace sh::fw
