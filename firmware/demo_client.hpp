// `stereohash-fw-sim --demo`: an in-process PLC on the simulated bus that reassembles every
// result set with the reference ResultAssembler and prints the poses as they arrive.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>

#include "hal/sim/can_sim_bus.hpp"
#include "recog/model/model.hpp"

namespace sh::fw {

class DemoClient {
 public:
  ~DemoClient() { Stop(); }
  // Joins `bus` listening to node `node_id`; names[i] labels model id i (may be null).
  Status Start(hal::SimCanBus* bus, uint8_t node_id, const char* const* names, int n_names);
  void Stop();

 private:
  void Run();
  hal::SimCanEndpoint* endpoint_ = nullptr;
  uint8_t node_ = 1;
  const char* const* names_ = nullptr;
  int n_names_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace sh::fw
