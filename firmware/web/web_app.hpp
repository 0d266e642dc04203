// The commissioning page's requests: the page's files, the status and live images, the actions
// and the settings (docs/web.md, API). Every request that changes something is a POST from a
// logged-in session that repeats the session's CSRF token in the X-CSRF-Token header; anything
// else is refused (403) and changes nothing. Requests beyond the rate limit get 429. Runs on the
// server thread only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/web/http_server.hpp"
#include "firmware/web/live_snapshot.hpp"
#include "firmware/web/overlay_edges.hpp"
#include "firmware/web/pair_capture.hpp"
#include "firmware/web/web_auth.hpp"
#include "firmware/web/web_settings.hpp"
#include "firmware/web/web_target.hpp"
#include "recog/camera/camera_model.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw::web {

inline constexpr const char* kSessionCookie = "sh_session";
inline constexpr const char* kCsrfHeader = "X-CSRF-Token";

struct WebAppConfig {
  const char* record_dir = "";    // recordings offered for download; "" = none
  const char* output_frame = "";  // name of the poses' frame
  bool https = false;             // served over TLS: the session cookie is Secure
  // Full-size pairs for the calibration helper (the worker feeds it), or nullptr (no helper).
  PairCapture* capture = nullptr;
  // The rig for the overlays, or nullptr (no overlays).
  const StereoCalibration* calibration = nullptr;
  // The working volume box, drawn on request: its corners in the frame left_T_volume maps into
  // the left camera.
  bool volume = false;
  RigidTransform left_T_volume;
  float volume_min_mm[3] = {0, 0, 0};
  float volume_max_mm[3] = {0, 0, 0};
};

// A token bucket: `rate` per second, at most `burst` saved up.
class RateLimit {
 public:
  RateLimit(uint32_t rate, uint32_t burst) : rate_(rate), burst_(burst), tokens_(burst) {}
  bool Take(int64_t now_ns);

 private:
  uint32_t rate_, burst_;
  double tokens_;
  int64_t last_ns_ = 0;
};

class WebApp final : public HttpHandler {
 public:
  WebApp(const WebAppConfig& config, WebAuth* auth, WebSettings* settings, LiveSnapshot* snapshot,
         WebTarget* target);
  void Handle(const HttpRequest& request, HttpResponse* response) override;
  // The same with the time given (tests).
  void HandleAt(const HttpRequest& request, int64_t now_ns, HttpResponse* response);

 private:
  void Get(const HttpRequest& request, int64_t now_ns, HttpResponse* response);
  void Post(const HttpRequest& request, int64_t now_ns, HttpResponse* response);
  void Action(const HttpRequest& request, HttpResponse* response);
  void Login(const HttpRequest& request, int64_t now_ns, HttpResponse* response);
  void ServeStatus(const HttpRequest& request, int64_t now_ns, HttpResponse* response);
  void Image(const HttpRequest& request, HttpResponse* response);
  void Recordings(const HttpRequest& request, HttpResponse* response);
  // The calibration helper: the captured chessboard pairs (list, one as a tar), and a capture.
  void CalibrationPairs(const HttpRequest& request, HttpResponse* response);
  void CaptureCalibrationPair(HttpResponse* response);
  // The size to prepare the capture for: the calibration's, else the last frames'.
  void CaptureSize(int* width, int* height) const;

  WebAppConfig config_;
  WebAuth* auth_;
  WebSettings* settings_;
  LiveSnapshot* snapshot_;
  WebTarget* target_;
  RateLimit rate_{kRequestsPerSecond, kRequestBurst};
  // The overlay of the result counted overlay_of_ (0: none yet): computed once per result, not
  // once per visitor and poll.
  std::vector<OverlayObject> overlay_;
  uint64_t overlay_of_ = 0;
  std::vector<std::vector<float>> volume_[2];  // the box's lines per image, if any
  std::vector<std::vector<float>> table_[2];   // the result's table plane per image, if any
  bool table_known_ = false;
};

// A JSON answer {"ok": ok, "message": text}.
void Reply(HttpResponse* response, int status, bool ok, const std::string& message);

}  // namespace sh::fw::web
