// Test rig for the firmware core: a simulated bus with the firmware's endpoint and a PLC
// endpoint, simulated GPIO and cameras, a deterministic recognition double.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <initializer_list>
#include <memory>
#include <optional>
#include <vector>

#include "firmware/data_source.hpp"
#include "firmware/firmware_core.hpp"
#include "firmware/plc/result_assembler.hpp"
#include "hal/sim/can_sim_bus.hpp"
#include "hal/sim/gpio_sim.hpp"
#include "hal/sim/sim_camera.hpp"

namespace sh::testing {

using namespace sh::fw;
using namespace sh::protocol;

// Frame n: every pixel n mod 256.
class PatternSource final : public hal::FrameSource {
 public:
  Status Open(int* w, int* h) override {
    *w = 64;
    *h = 48;
    return Status::Ok();
  }
  Status Render(uint64_t n, GrayView left, GrayView right) override {
    for (int y = 0; y < left.height; ++y) {
      for (int x = 0; x < left.width; ++x) left.at(x, y) = right.at(x, y) = uint8_t(n);
    }
    return Status::Ok();
  }
};

// One object per frame: model 0 at x = frame sequence mm; records the mask it was given.
class FakeRecognition final : public Recognition {
 public:
  Status Init(const StereoCalibration&, const ModelSet& models, uint32_t mask) override {
    ++inits;
    this->mask = mask;
    return Status::Ok();
  }
  Status SetModelMask(uint32_t m) override {
    mask = m;
    return Status::Ok();
  }
  Status Process(const hal::StereoFrame& frame, float budget, ResultSet* set) override {
    last_budget_ms = budget;
    if (fail_next.exchange(false)) {
      return Status::Error(StatusCode::kInternal, "injected recognition failure");
    }
    RigidTransform T;
    T.t_mm = Eigen::Vector3f(float(frame.left_sequence), 0, 500);
    set->objects[0] = MakeObjectPose(T, 0, 0, 0.5);
    set->object_count = 1;
    set->status = ResultStatus::kOk;
    return Status::Ok();
  }
  std::atomic<int> inits{0};
  std::atomic<uint32_t> mask{0};
  std::atomic<float> last_budget_ms{0};
  std::atomic<bool> fail_next{false};
};

// A simulated bus with the firmware's endpoint (no filter, as on the board) and a PLC's.
struct PlcBus {
  PlcBus() {
    fw = *bus.AddEndpoint(hal::SimCanEndpointConfig{});
    hal::SimCanEndpointConfig plc_config;
    plc_config.name = "plc";
    plc = *bus.AddEndpoint(plc_config);
  }
  hal::SimCanBus bus;
  hal::SimCanEndpoint* fw = nullptr;
  hal::SimCanEndpoint* plc = nullptr;
};

// The devices a firmware test wires to its core: the firmware's bus endpoint, GPIO (may be null),
// the cameras, the recognition, the data and an observer (may be null).
inline CoreDevices SimCoreDevices(hal::CanBus* can, hal::Gpio* gpio, hal::StereoCamera* camera,
                                  Recognition* recognition, DataSource* data,
                                  CoreObserver* observer = nullptr) {
  CoreDevices d;
  d.can = can;
  d.gpio = gpio;
  d.camera = camera;
  d.recognition = recognition;
  d.data = data;
  d.observer = observer;
  return d;
}

// A command frame to node `node` carrying `bytes` (docs/can-protocol.md, Commands).
inline hal::CanFrame CommandFrame(uint8_t node, std::initializer_list<uint8_t> bytes) {
  hal::CanFrame f;
  f.id = kCobCommand + node;
  for (uint8_t b : bytes) {
    if (f.len == sizeof(f.data)) break;  // a CAN frame holds 8 bytes: the rest is not sent
    f.data[f.len++] = b;
  }
  return f;
}
// Trigger (0x01) with a request id: its low byte, as the PLC of the tests counts.
inline hal::CanFrame TriggerFrame(uint8_t node, uint8_t request_id) {
  return CommandFrame(node, {0x01, request_id, 0});
}
// Select models (0x02): the mask, little-endian.
inline hal::CanFrame SelectModelsFrame(uint8_t node, uint32_t mask) {
  return CommandFrame(
      node, {0x02, uint8_t(mask), uint8_t(mask >> 8), uint8_t(mask >> 16), uint8_t(mask >> 24)});
}

// Receives at `plc` (10 ms polls, at most `polls`) until `assembler` completes a verified result
// set, copied to *out; false if none completed.
inline bool WaitResultSet(hal::SimCanEndpoint* plc, ResultAssembler* assembler, ResultSet* out,
                          int polls) {
  for (int i = 0; i < polls; ++i) {
    hal::CanFrame f;
    Result<bool> got = plc->Receive(&f, 10);
    if (!got.ok() || !*got) continue;
    Result<bool> done = assembler->Feed(f);
    if (done.ok() && *done) {
      *out = assembler->set();
      return true;
    }
  }
  return false;
}

class Rig {
 public:
  explicit Rig(const hal::SimCameraConfig& camera_config = {}) {
    // No filter, as on the board: the core picks its identifiers (they follow LSS changes).
    fw = *bus.AddEndpoint(hal::SimCanEndpointConfig{});
    hal::SimCanEndpointConfig plc_config;
    plc_config.name = "plc";
    plc = *bus.AddEndpoint(plc_config);
    camera = std::make_unique<hal::SimCamera>(&source, camera_config);
    calib.left.width = calib.right.width = 64;
    calib.left.height = calib.right.height = 48;
    data = std::make_unique<FileDataSource>("builtin", "", &calib);
    config.node_id = kNode;
    config.heartbeat_ms = 20;
    config.capture_timeout_ms = 500;  // generous: tests also run under qemu
  }
  ~Rig() { core.Stop(); }

  void Start() {
    CoreDevices d = SimCoreDevices(fw, &gpio, camera.get(), &recognition, data.get());
    d.lss_store = lss_store;
    d.recorder = recorder;
    const Status s = core.Start(config, d);
    ASSERT_TRUE(s.ok()) << s.message();
  }

  // Receives at the PLC until a frame with this id (and, if given, this first byte) arrives.
  std::optional<hal::CanFrame> WaitFor(uint32_t function_code, int first_byte = -1,
                                       int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (std::chrono::steady_clock::now() < end) {
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 20);
      if (!got.ok() || !*got) continue;
      Feed(f);
      if (f.id == function_code + kNode && (first_byte < 0 || f.data[0] == first_byte)) return f;
    }
    return std::nullopt;
  }

  // Next EMCY with this code, including those received while waiting for something else.
  std::optional<Emcy> WaitEmcy(uint16_t code, int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (true) {
      while (emcy_read_ < emcys_.size()) {
        const Emcy e = emcys_[emcy_read_++];
        if (e.error_code == code) return e;
      }
      if (std::chrono::steady_clock::now() >= end) return std::nullopt;
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 20);
      if (got.ok() && *got) Feed(f);
    }
  }

  std::optional<CommandAck> WaitAck(uint8_t code) {
    std::optional<hal::CanFrame> f = WaitFor(kCobCommandAck, code);
    if (!f) return std::nullopt;
    Result<CommandAck> a = DecodeCommandAck(*f, kNode);
    if (!a.ok()) return std::nullopt;
    return *a;
  }

  // Waits for a complete, verified result set newer than the last one returned (it may have
  // arrived while the rig was waiting for another frame).
  std::optional<ResultSet> WaitSet(int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (std::chrono::steady_clock::now() < end && sets_done_ == sets_returned_) {
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 20);
      if (got.ok() && *got) Feed(f);
    }
    if (sets_done_ == sets_returned_) return std::nullopt;
    sets_returned_ = sets_done_;
    return last_set_;
  }

  // The next set answering `request_id`. Sets of earlier triggers are skipped: one may come
  // through whole while a fault is injected, when the other threads' frames take the failures.
  std::optional<ResultSet> WaitSetFor(uint16_t request_id, int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          end - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      std::optional<ResultSet> s = WaitSet(static_cast<int>(left.count()));
      if (!s || s->request_id == request_id) return s;
    }
  }

  void Command(std::initializer_list<uint8_t> bytes) {
    ASSERT_TRUE(plc->Send(CommandFrame(kNode, bytes)).ok());
  }
  void Trigger(uint16_t request_id) {
    Command({0x01, uint8_t(request_id), uint8_t(request_id >> 8), 0, 0, 0, 0, 0});
  }
  void ClearFault() { Command({0x04, 0, 0, 0, 0, 0, 0, 0}); }
  // An NMT command to `node` (the rig's node by default).
  void Nmt(NmtCommand command, uint8_t node = kNode) {
    hal::CanFrame f;
    f.id = kCobNmt;
    f.len = 2;
    f.data[0] = uint8_t(command);
    f.data[1] = node;
    ASSERT_TRUE(plc->Send(f).ok());
  }
  // An LSS request (8 bytes, the rest zero) and the next LSS response with command specifier
  // `cs`.
  void Lss(std::initializer_list<uint8_t> bytes) {
    hal::CanFrame f;
    f.id = canopen::kLssMasterCobId;
    f.len = 8;
    size_t i = 0;
    for (uint8_t b : bytes) f.data[i++] = b;
    ASSERT_TRUE(plc->Send(f).ok());
  }
  std::optional<hal::CanFrame> WaitLss(uint8_t cs, int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (std::chrono::steady_clock::now() < end) {
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 10);
      if (!got.ok() || !*got) continue;
      Feed(f);
      if (f.id == canopen::kLssSlaveCobId && f.data[0] == cs) return f;
    }
    return std::nullopt;
  }

  bool WaitState(FirmwareState s, int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (std::chrono::steady_clock::now() < end) {
      if (core.state() == s) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return core.state() == s;
  }

  // True once `n` operational-or-fault heartbeats reached the PLC; false if they did not within
  // the timeout (generous: the rig also runs under qemu on a loaded machine).
  bool SeeHeartbeats(int n, int timeout_ms = 15000) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    int seen = 0;
    while (seen < n && std::chrono::steady_clock::now() < end) {
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 10);
      if (!got.ok() || !*got) continue;
      Feed(f);
      if (f.id == kCobHeartbeat + kNode && f.len == 1 && f.data[0] != 0) ++seen;
    }
    return seen >= n;
  }

  // A data fault at boot: its EMCY with `detail`, the fault state, no recognition initialised,
  // and the heartbeat going on.
  void ExpectBootDataFault(uint8_t detail) {
    const std::optional<Emcy> e = WaitEmcy(uint16_t(EmcyCode::kDataSet));
    ASSERT_TRUE(e);
    EXPECT_EQ(e->detail, detail);
    EXPECT_EQ(core.state(), FirmwareState::kFault);
    EXPECT_EQ(recognition.inits.load(), 0);
    EXPECT_TRUE(SeeHeartbeats(2));
  }

  // Heartbeats seen by the PLC within `ms`.
  int CountHeartbeats(int ms) {
    int n = 0;
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (std::chrono::steady_clock::now() < end) {
      hal::CanFrame f;
      Result<bool> got = plc->Receive(&f, 10);
      if (!got.ok() || !*got) continue;
      Feed(f);
      if (f.id == kCobHeartbeat + kNode && f.len == 1 && f.data[0] != 0) ++n;
    }
    return n;
  }

  void Feed(const hal::CanFrame& f) {
    if (f.id == kCobEmcy + kNode) {
      Result<Emcy> e = DecodeEmcy(f, kNode);
      if (e.ok()) emcys_.push_back(*e);
    }
    Result<bool> done = assembler.Feed(f);
    if (!done.ok()) ++broken_sets;
    if (done.ok() && *done) {
      last_set_ = assembler.set();
      ++sets_done_;
    }
  }

  // Result sets completed so far, including those seen while waiting for something else.
  int sets_completed() const { return sets_done_; }

  static constexpr uint8_t kNode = 5;
  hal::SimCanBus bus;
  hal::SimCanEndpoint* fw = nullptr;
  hal::SimCanEndpoint* plc = nullptr;
  hal::SimGpio gpio;
  PatternSource source;
  std::unique_ptr<hal::SimCamera> camera;
  FakeRecognition recognition;
  StereoCalibration calib;
  std::unique_ptr<FileDataSource> data;
  CoreConfig config;
  canopen::LssStore* lss_store = nullptr;
  Recorder* recorder = nullptr;
  FirmwareCore core;
  ResultAssembler assembler{kNode};
  int broken_sets = 0;

 private:
  ResultSet last_set_;
  std::vector<Emcy> emcys_;
  size_t emcy_read_ = 0;
  int sets_done_ = 0, sets_returned_ = 0;
};

}  // namespace sh::testing
