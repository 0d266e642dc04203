// The page's status document (GET /api/status): health (state, NMT, heartbeat, faults, EMCY
// history with its text, camera and CAN counters, recording), the last result set with its
// overlay, and what the visitor may do (login state, CSRF token).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/web/live_snapshot.hpp"
#include "firmware/web/overlay_edges.hpp"
#include "firmware/web/web_target.hpp"

namespace sh::fw::web {

struct StatusAccess {
  bool login_possible = false;  // a password is configured
  bool logged_in = false;
  std::string csrf;  // the session's token, when logged in
};

// Meaning of an EMCY error code (0x1003 entries, EMCY messages).
const char* EmcyCodeText(uint16_t code);

// Lines to draw over the left and right image (polylines in full-size pixels).
using ImageLines = std::vector<std::vector<float>>;

struct StatusOverlay {
  const std::vector<OverlayObject>* objects = nullptr;  // one per object of the result
  const ImageLines* volume = nullptr;  // [2]: the working volume's box, or nullptr (none)
  const ImageLines* table = nullptr;   // [2]: the result's table plane, or nullptr (none)
};

std::string StatusJson(const WebHealth& health, const LiveResult& result,
                       const StatusOverlay& overlay, const char* output_frame, int64_t now_ns,
                       const StatusAccess& access);

}  // namespace sh::fw::web
