// Stand-in CAN device for end-to-end tests: a simulated bus with a socketcand server and a node
// that speaks the stereohash PLC protocol with fake-but-valid poses.
//
// stdout, one line each (flushed):
//   SOCKETCAND_PORT=<port>                  once the server listens
//   RESULT {json}                           every result set sent, values as given to the encoder
//   EMCY {json}                             every EMCY sent
// Behaviour: waits for the first socketcand client in raw mode (--wait-for-client), sends the
// boot-up, enters operational (self-starting node), sends heartbeats, answers commands with an
// acknowledge, rejected commands additionally with an EMCY, and each trigger with a result set.
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "firmware/canopen/cob_id.hpp"
#include "firmware/canopen/emcy.hpp"
#include "firmware/canopen/nmt.hpp"
#include "firmware/command_codec.hpp"
#include "firmware/result_codec.hpp"
#include "firmware/result_json.hpp"
#include "hal/can_log.hpp"
#include "hal/sim/can_sim_bus.hpp"
#include "hal/sim/socketcand_server.hpp"

namespace {

using namespace sh;
using namespace sh::protocol;

volatile sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

int64_t NowMs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000 + ts.tv_nsec / 1000000;
}

struct Options {
  int node_id = 1;
  int port = 0;
  int heartbeat_ms = 200;
  int run_seconds = 120;  // safety net so an abandoned process ends
  bool wait_for_client = true;
  const char* candump = nullptr;
};

bool ParseOptions(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    auto value = [&](int* out) {
      if (i + 1 >= argc) return false;
      char* end = nullptr;
      *out = static_cast<int>(std::strtol(argv[++i], &end, 10));
      return *end == '\0';
    };
    if (!std::strcmp(argv[i], "--node")) {
      if (!value(&o->node_id)) return false;
    } else if (!std::strcmp(argv[i], "--port")) {
      if (!value(&o->port)) return false;
    } else if (!std::strcmp(argv[i], "--heartbeat-ms")) {
      if (!value(&o->heartbeat_ms)) return false;
    } else if (!std::strcmp(argv[i], "--run-seconds")) {
      if (!value(&o->run_seconds)) return false;
    } else if (!std::strcmp(argv[i], "--no-wait")) {
      o->wait_for_client = false;
    } else if (!std::strcmp(argv[i], "--candump") && i + 1 < argc) {
      o->candump = argv[++i];
    } else {
      return false;
    }
  }
  return o->node_id >= 1 && o->node_id <= 127 && o->port >= 0 && o->port <= 65535 &&
         o->heartbeat_ms > 0;
}

class DemoNode {
 public:
  DemoNode(hal::CanBus* bus, uint8_t node_id) : bus_(bus), node_(node_id), rng_(node_id) {}

  void Send(const Result<hal::CanFrame>& frame) {
    if (!frame.ok()) {
      std::fprintf(stderr, "can_sim_demo: encode failed: %s\n", frame.status().message());
      return;
    }
    const Status s = bus_->Send(*frame);
    if (!s.ok()) std::fprintf(stderr, "can_sim_demo: send failed: %s\n", s.message());
  }

  void BootUp() {
    Send(EncodeBootUp(node_));
    state_ = NmtState::kOperational;  // self-starting node
  }
  void Heartbeat() { Send(EncodeHeartbeat(node_, state_)); }

  void SendEmcy(const Emcy& e) {
    Send(EncodeEmcy(e, node_));
    std::printf(
        "EMCY {\"error_code\": %u, \"error_register\": %u, \"state\": %u, \"detail\": %u}\n",
        e.error_code, e.error_register, static_cast<unsigned>(e.state), e.detail);
    std::fflush(stdout);
  }

  void OnFrame(const hal::CanFrame& frame) {
    if (frame.id == kCobNmt) {
      Result<NmtRequest> nmt = DecodeNmt(frame, node_);
      if (!nmt.ok() || !nmt->addressed) return;
      switch (nmt->command) {
        case NmtCommand::kStart:
          state_ = NmtState::kOperational;
          break;
        case NmtCommand::kStop:
          state_ = NmtState::kStopped;
          break;
        case NmtCommand::kEnterPreOperational:
          state_ = NmtState::kPreOperational;
          break;
        case NmtCommand::kResetNode:
        case NmtCommand::kResetCommunication:
          BootUp();
          break;
      }
      Heartbeat();
      return;
    }
    if (frame.id != kCobCommand + node_) return;
    if (state_ != NmtState::kOperational) return;  // RPDOs count only when operational
    Result<Command> cmd = DecodeCommand(frame, node_);
    Send(EncodeCommandAck(MakeCommandAck(frame, cmd.status()), node_));
    if (!cmd.ok()) {
      std::fprintf(stderr, "can_sim_demo: command rejected: %s\n", cmd.status().message());
      SendEmcy(MakeCommandRejectedEmcy(frame, cmd.status(), FirmwareState::kReady));
      return;
    }
    switch (cmd->code) {
      case CommandCode::kTrigger:
        SendResult(cmd->request_id);
        break;
      case CommandCode::kSelectModels:
        model_mask_ = cmd->model_mask;
        break;
      case CommandCode::kSetTimeBudget:
        break;
      case CommandCode::kClearFault: {
        Emcy reset;
        reset.state = FirmwareState::kReady;
        SendEmcy(reset);
        break;
      }
      case CommandCode::kSetFreeRunRate:
        break;
    }
  }

 private:
  // Fake but valid poses: random unit quaternions (sometimes with w < 0, which the encoder
  // canonicalises), positions of either sign, models from the selected mask.
  void SendResult(uint16_t request_id) {
    static ResultSet set;
    set = ResultSet();
    set.sequence = sequence_++;
    set.request_id = request_id;
    std::uniform_int_distribution<int> count_dist(0, 5);
    std::uniform_real_distribution<double> xy(-800.0, 800.0), z(250.0, 1800.0), unit(0.0, 1.0);
    std::normal_distribution<double> gauss(0.0, 1.0);
    set.object_count = static_cast<uint8_t>(count_dist(rng_));
    set.processing_time_us = static_cast<uint32_t>(20000 + unit(rng_) * 100000);
    uint8_t instances[32] = {};
    for (uint8_t i = 0; i < set.object_count; ++i) {
      ObjectPose& p = set.objects[i];
      uint8_t model = 0;
      do {
        model = static_cast<uint8_t>(rng_() % 32);
      } while (!(model_mask_ & (1u << model)));
      p.model_id = model;
      p.instance = instances[model]++;
      p.score = std::round(unit(rng_) * 1e6) / 1e6;
      p.cam_t_model_mm[0] = xy(rng_);
      p.cam_t_model_mm[1] = xy(rng_);
      p.cam_t_model_mm[2] = z(rng_);
      double n = 0;
      for (double& q : p.cam_q_model) {
        q = gauss(rng_);
        n += q * q;
      }
      for (double& q : p.cam_q_model) q /= std::sqrt(n);
    }
    static Vector<hal::CanFrame, kMaxResultFrames> frames;
    frames.clear();
    const Status s = EncodeResultSet(set, node_, frames);
    if (!s.ok()) {
      std::fprintf(stderr, "can_sim_demo: result encoding failed: %s\n", s.message());
      return;
    }
    for (const hal::CanFrame& f : frames) Send(f);
    std::printf("RESULT {");
    WriteResultSetJsonFields(stdout, set);
    std::printf("}\n");
    std::fflush(stdout);
  }

  hal::CanBus* bus_;
  uint8_t node_;
  std::mt19937 rng_;
  NmtState state_ = NmtState::kPreOperational;
  uint16_t sequence_ = 0;
  uint32_t model_mask_ = 0x0000000Fu;
};

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (!ParseOptions(argc, argv, &options)) {
    std::fprintf(stderr,
                 "usage: can_sim_demo [--node 1..127] [--port P (0 = ephemeral)] "
                 "[--heartbeat-ms T] [--run-seconds S] [--no-wait] [--candump FILE]\n");
    return 2;
  }
  signal(SIGTERM, OnSignal);
  signal(SIGINT, OnSignal);

  static hal::SimCanBus bus;
  const uint8_t node = static_cast<uint8_t>(options.node_id);
  hal::SimCanEndpointConfig fw_config;
  fw_config.name = "can0";
  fw_config.filter_ids[0] = kCobNmt;
  fw_config.filter_ids[1] = kCobCommand + node;
  fw_config.filter_count = 2;
  Result<hal::SimCanEndpoint*> fw = bus.AddEndpoint(fw_config);
  if (!fw.ok()) {
    std::fprintf(stderr, "can_sim_demo: %s\n", fw.status().message());
    return 1;
  }
  static hal::SocketcandServer server;
  hal::SocketcandServerConfig server_config;
  server_config.port = static_cast<uint16_t>(options.port);
  const Status started = server.Start(&bus, server_config);
  if (!started.ok()) {
    std::fprintf(stderr, "can_sim_demo: %s\n", started.message());
    return 1;
  }
  FILE* candump = nullptr;
  if (options.candump != nullptr) {
    candump = std::fopen(options.candump, "w");
    if (candump == nullptr) {
      std::fprintf(stderr, "can_sim_demo: cannot write %s\n", options.candump);
      return 1;
    }
  }
  hal::CandumpLogger logged(*fw, candump != nullptr ? candump : stderr, true);
  hal::CanBus* bus_of_node = candump != nullptr ? static_cast<hal::CanBus*>(&logged) : *fw;

  std::printf("SOCKETCAND_PORT=%u\n", server.port());
  std::fflush(stdout);
  const int64_t end_ms = NowMs() + static_cast<int64_t>(options.run_seconds) * 1000;
  while (options.wait_for_client && server.raw_mode_clients() == 0 && !g_stop && NowMs() < end_ms) {
    usleep(2000);
  }

  DemoNode demo(bus_of_node, node);
  demo.BootUp();
  int64_t next_heartbeat = NowMs() + options.heartbeat_ms;
  while (!g_stop && NowMs() < end_ms) {
    const int64_t wait = next_heartbeat - NowMs();
    hal::CanFrame frame;
    Result<bool> got = bus_of_node->Receive(&frame, wait > 0 ? static_cast<int>(wait) : 0);
    if (!got.ok()) {
      std::fprintf(stderr, "can_sim_demo: receive failed: %s\n", got.status().message());
      break;
    }
    if (*got) demo.OnFrame(frame);
    if (NowMs() >= next_heartbeat) {
      demo.Heartbeat();
      next_heartbeat += options.heartbeat_ms;
    }
  }
  server.Stop();
  if (candump != nullptr) std::fclose(candump);
  return 0;
}
