// The node id stored by LSS ("store configuration"): one decimal number in a small file that
// the firmware reads at boot (it overrides the configured node_id). Written to a temporary file
// and renamed, so a power cut leaves the old or the new id, never half a file.
#pragma once

#include <cstdint>

#include "firmware/canopen/lss_slave.hpp"
#include "firmware/fw_config.hpp"
#include "recog/base/status.hpp"

namespace sh::fw {

// kNotFound if there is no file yet; kInvalidArgument if it holds no node id 1..127.
Result<uint8_t> ReadNodeIdFile(const char* path);

class NodeIdFile final : public canopen::LssStore {
 public:
  explicit NodeIdFile(const char* path);
  Status StoreNodeId(uint8_t node_id) override;

 private:
  char path_[kConfigPathMax] = {};
};

}  // namespace sh::fw
