#include "firmware/web/web_app.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "firmware/canopen/eds_writer.hpp"
#include "firmware/web/calibration_pairs.hpp"
#include "firmware/web/json_writer.hpp"
#include "firmware/web/png_encode.hpp"
#include "firmware/web/recordings.hpp"
#include "firmware/web/status_json.hpp"
#include "firmware/web/web_assets.hpp"

namespace sh::fw::web {
namespace {

// HTTP status of a refused action.
int HttpStatusOf(const sh::Status& s) {
  switch (s.code()) {
    case StatusCode::kInvalidArgument:
    case StatusCode::kOutOfRange:
      return 400;
    case StatusCode::kNotFound:
      return 404;
    case StatusCode::kResourceExhausted:
    case StatusCode::kUnavailable:
      return 503;
    default:
      return 409;
  }
}

// A whole number argument in lo..hi, or -1.
long ArgumentIn(const HttpRequest& request, const char* name, long lo, long hi) {
  const char* text = request.Argument(name);
  if (text == nullptr || *text == '\0') return -1;
  char* end = nullptr;
  const long v = std::strtol(text, &end, 10);
  return *end == '\0' && v >= lo && v <= hi ? v : -1;
}

std::string EdsText() {
  char* buffer = nullptr;
  size_t bytes = 0;
  FILE* out = open_memstream(&buffer, &bytes);
  if (out == nullptr) return std::string();
  const bool ok = canopen::WriteEds(out).ok();
  std::fclose(out);
  std::string text = ok ? std::string(buffer, bytes) : std::string();
  std::free(buffer);
  return text;
}

}  // namespace

void Reply(HttpResponse* response, int status, bool ok, const std::string& message) {
  JsonWriter j;
  j.BeginObject().Key("ok").Bool(ok).Key("message").String(message.c_str()).EndObject();
  response->status = status;
  response->content_type = "application/json";
  response->body = j.text();
}

bool RateLimit::Take(int64_t now_ns) {
  if (last_ns_ != 0 && now_ns > last_ns_) {
    tokens_ += double(now_ns - last_ns_) * 1e-9 * rate_;
    if (tokens_ > burst_) tokens_ = burst_;
  }
  last_ns_ = now_ns;
  if (tokens_ < 1.0) return false;
  tokens_ -= 1.0;
  return true;
}

WebApp::WebApp(const WebAppConfig& config, WebAuth* auth, WebSettings* settings,
               LiveSnapshot* snapshot, WebTarget* target)
    : config_(config), auth_(auth), settings_(settings), snapshot_(snapshot), target_(target) {
  if (config_.calibration != nullptr && config_.volume) {
    for (int side = 0; side < 2; ++side) {
      volume_[side] = VolumeLines(*config_.calibration, config_.left_T_volume,
                                  config_.volume_min_mm, config_.volume_max_mm, side);
    }
  }
}

void WebApp::Handle(const HttpRequest& request, HttpResponse* response) {
  HandleAt(request, MonotonicNs(), response);
}

void WebApp::HandleAt(const HttpRequest& request, int64_t now_ns, HttpResponse* response) {
  if (!rate_.Take(now_ns)) return Reply(response, 429, false, "too many requests");
  if (std::strcmp(request.method, "GET") == 0 || std::strcmp(request.method, "HEAD") == 0) {
    return Get(request, now_ns, response);
  }
  if (std::strcmp(request.method, "POST") == 0) return Post(request, now_ns, response);
  Reply(response, 405, false, "method not allowed");
}

void WebApp::Get(const HttpRequest& request, int64_t now_ns, HttpResponse* response) {
  const char* path = request.path;
  if (const Asset* asset = FindAsset(path)) {
    response->content_type = asset->content_type;
    response->static_data = asset->data;
    response->static_bytes = asset->bytes;
    return;
  }
  if (!std::strcmp(path, "/api/status")) return ServeStatus(request, now_ns, response);
  if (!std::strcmp(path, "/api/image")) return Image(request, response);
  if (!std::strcmp(path, "/api/settings")) {
    response->content_type = "application/json";
    response->body = settings_->Json();
    return;
  }
  if (!std::strcmp(path, "/api/recordings")) return Recordings(request, response);
  if (!std::strcmp(path, "/api/calibration")) return CalibrationPairs(request, response);
  if (!std::strcmp(path, "/api/eds")) {
    response->body = EdsText();
    response->content_disposition = "attachment; filename=stereohash.eds";
    return;
  }
  if (!std::strcmp(path, "/api/dbc")) {
    const Asset dbc = DbcAsset();
    response->static_data = dbc.data;
    response->static_bytes = dbc.bytes;
    response->content_disposition = "attachment; filename=stereohash.dbc";
    return;
  }
  Reply(response, 404, false, "not found");
}

void WebApp::ServeStatus(const HttpRequest& request, int64_t now_ns, HttpResponse* response) {
  StatusAccess access;
  access.login_possible = auth_->enabled();
  access.logged_in = auth_->Authenticated(request.Cookie(kSessionCookie), now_ns, &access.csrf);
  const LiveResult result = snapshot_->Result();
  if (result.results != overlay_of_) {
    table_known_ =
        config_.calibration != nullptr && result.set.table != protocol::TablePlane::kNone;
    if (config_.calibration != nullptr) {
      overlay_ = ComputeOverlay(*config_.calibration, *snapshot_, result.set);
      for (int side = 0; side < 2 && table_known_; ++side) {
        table_[side] = TableGridLines(*config_.calibration, result.set.left_T_table, side);
      }
    } else {
      overlay_.assign(result.set.object_count, OverlayObject());
    }
    overlay_of_ = result.results;
  }
  response->content_type = "application/json";
  StatusOverlay overlay;
  overlay.objects = &overlay_;
  if (config_.calibration != nullptr && config_.volume) overlay.volume = volume_;
  if (table_known_) overlay.table = table_;
  response->body =
      StatusJson(target_->Health(), result, overlay, config_.output_frame, now_ns, access);
}

void WebApp::Image(const HttpRequest& request, HttpResponse* response) {
  const char* side = request.Argument("side");
  const int s = side != nullptr && !std::strcmp(side, "right") ? 1 : 0;
  LiveImage image;
  if (!snapshot_->Image(s, &image)) return Reply(response, 404, false, "no image yet");
  std::vector<uint8_t> png;
  const sh::Status encoded = EncodeGrayPng(image.pixels.data(), image.width, image.height, &png);
  if (!encoded.ok()) return Reply(response, 500, false, encoded.message());
  response->content_type = "image/png";
  response->body.assign(png.begin(), png.end());
}

void WebApp::Recordings(const HttpRequest& request, HttpResponse* response) {
  if (config_.record_dir[0] == '\0') return Reply(response, 404, false, "record_dir is not set");
  const char* pair = request.Argument("pair");
  if (pair == nullptr) {
    JsonWriter j;
    j.BeginArray();
    for (const std::string& name : ListPairs(config_.record_dir, 50)) j.String(name.c_str());
    j.EndArray();
    response->content_type = "application/json";
    response->body = j.text();
    return;
  }
  // Only 8-digit names reach the file system: nothing outside record_dir can be named.
  const sh::Status s = ArchivePair(config_.record_dir, pair, &response->body);
  if (!s.ok()) return Reply(response, HttpStatusOf(s), false, s.message());
  response->content_type = "application/x-tar";
  response->content_disposition = std::string("attachment; filename=") + pair + ".tar";
}

void WebApp::CalibrationPairs(const HttpRequest& request, HttpResponse* response) {
  if (config_.record_dir[0] == '\0') return Reply(response, 404, false, "record_dir is not set");
  const char* pair = request.Argument("pair");
  if (pair == nullptr) {
    JsonWriter j;
    j.BeginObject().Key("folder").String(CalibrationDir(config_.record_dir).c_str());
    j.Key("pairs").BeginArray();
    for (const std::string& name : ListCalibrationPairs(config_.record_dir)) {
      j.String(name.c_str());
    }
    j.EndArray().EndObject();
    response->content_type = "application/json";
    response->body = j.text();
    return;
  }
  // Only 8-digit names reach the file system: nothing outside the folder can be named.
  const sh::Status s =
      ArchivePair(CalibrationDir(config_.record_dir).c_str(), pair, &response->body);
  if (!s.ok()) return Reply(response, HttpStatusOf(s), false, s.message());
  response->content_type = "application/x-tar";
  response->content_disposition = std::string("attachment; filename=calibration-") + pair + ".tar";
}

void WebApp::CaptureSize(int* width, int* height) const {
  *width = *height = 0;
  if (config_.calibration != nullptr) {
    *width = std::max(config_.calibration->left.width, config_.calibration->right.width);
    *height = std::max(config_.calibration->left.height, config_.calibration->right.height);
    return;
  }
  const LiveResult last = snapshot_->Result();
  *width = std::max(last.full_width[0], last.full_width[1]);
  *height = std::max(last.full_height[0], last.full_height[1]);
}

void WebApp::CaptureCalibrationPair(HttpResponse* response) {
  if (config_.record_dir[0] == '\0') {
    return Reply(response, 404, false, "record_dir is not set: the pairs are written under it");
  }
  if (config_.capture == nullptr) return Reply(response, 503, false, "no capture on this page");
  int width = 0, height = 0;
  CaptureSize(&width, &height);
  sh::Status s = config_.capture->Prepare(width, height);
  if (!s.ok()) return Reply(response, HttpStatusOf(s), false, s.message());
  config_.capture->Arm();
  // A trigger for the pair; in continuous mode the next frame serves as well (a refused trigger
  // is then no error).
  const sh::Status triggered = target_->Trigger();
  for (int waited_ms = 0; waited_ms < kCaptureWaitMs && !config_.capture->ready();
       waited_ms += 10) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!config_.capture->ready()) {
    config_.capture->Disarm();
    if (!config_.capture->ready()) {
      return Reply(response, 503, false,
                   std::string("no pair with both images came within the wait") +
                       (triggered.ok() ? "" : std::string(": ") + triggered.message()));
    }
  }
  const Result<SavedPair> saved = SaveCalibrationPair(config_.record_dir, *config_.capture);
  if (!saved.ok()) {
    return Reply(response, HttpStatusOf(saved.status()), false, saved.status().message());
  }
  const std::string message = "pair " + saved->name + " captured (" + std::to_string(saved->pairs) +
                              " in the calibration folder)";
  JsonWriter j;
  j.BeginObject().Key("ok").Bool(true).Key("message").String(message.c_str());
  j.Key("pair").String(saved->name.c_str()).Key("pairs").Uint(saved->pairs);
  j.EndObject();
  response->content_type = "application/json";
  response->body = j.text();
}

void WebApp::Login(const HttpRequest& request, int64_t now_ns, HttpResponse* response) {
  const Result<LoginTokens> tokens = auth_->Login(request.body, request.body_bytes, now_ns);
  if (!tokens.ok()) {
    const int status = tokens.status().code() == StatusCode::kUnavailable ? 429 : 403;
    return Reply(response, status, false, tokens.status().message());
  }
  // Over HTTPS the browser must never send the session in clear.
  response->set_cookie = std::string(kSessionCookie) + "=" + tokens->session +
                         "; Path=/; HttpOnly; SameSite=Strict" + (config_.https ? "; Secure" : "");
  JsonWriter j;
  j.BeginObject().Key("ok").Bool(true).Key("csrf").String(tokens->csrf.c_str()).EndObject();
  response->content_type = "application/json";
  response->body = j.text();
}

void WebApp::Post(const HttpRequest& request, int64_t now_ns, HttpResponse* response) {
  if (!std::strcmp(request.path, "/api/login")) return Login(request, now_ns, response);
  if (!auth_->enabled()) {
    return Reply(response, 403, false, "read-only: no password is configured (http_password)");
  }
  const std::string session = request.Cookie(kSessionCookie);
  if (!auth_->Authorised(session, request.Header(kCsrfHeader), now_ns)) {
    return Reply(response, 403, false, "log in first (or the page's token is stale: reload)");
  }
  if (!std::strcmp(request.path, "/api/logout")) {
    auth_->Logout(session);
    response->set_cookie = std::string(kSessionCookie) + "=; Path=/; Max-Age=0";
    return Reply(response, 200, true, "logged out");
  }
  Action(request, response);
}

void WebApp::Action(const HttpRequest& request, HttpResponse* response) {
  const char* path = request.path;
  if (!std::strcmp(path, "/api/trigger")) {
    const sh::Status s = target_->Trigger();
    return Reply(response, s.ok() ? 200 : HttpStatusOf(s), s.ok(),
                 s.ok() ? "triggered" : s.message());
  }
  if (!std::strcmp(path, "/api/continuous")) {
    const long rate = ArgumentIn(request, "rate_dhz", 0, protocol::kFreeRunRateMaxDeciHz);
    if (rate < 0) return Reply(response, 400, false, "rate_dhz: expected 0..the free-run maximum");
    target_->SetFreeRun(static_cast<uint16_t>(rate));
    return Reply(response, 200, true, rate ? "continuous" : "stopped");
  }
  if (!std::strcmp(path, "/api/record")) {
    const long pairs = ArgumentIn(request, "pairs", 1, kMaxRecordRequest);
    if (pairs < 0) return Reply(response, 400, false, "pairs: expected 1..100");
    const sh::Status s = target_->RecordNext(static_cast<int>(pairs));
    return Reply(response, s.ok() ? 200 : HttpStatusOf(s), s.ok(),
                 s.ok() ? "the next triggered pairs are recorded" : s.message());
  }
  if (!std::strcmp(path, "/api/calibration/capture")) return CaptureCalibrationPair(response);
  if (!std::strcmp(path, "/api/clear-fault")) {
    target_->ClearFault();
    return Reply(response, 200, true, "clear-fault requested");
  }
  if (!std::strcmp(path, "/api/settings")) {
    std::string report;
    const sh::Status s = settings_->Change(request.body, request.body_bytes, target_, &report);
    return Reply(response, s.ok() ? 200 : HttpStatusOf(s), s.ok(), s.ok() ? report : s.message());
  }
  if (!std::strcmp(path, "/api/settings/save")) {
    const sh::Status s = settings_->Save();
    return Reply(response, s.ok() ? 200 : HttpStatusOf(s), s.ok(),
                 s.ok() ? "written to the configuration file" : s.message());
  }
  Reply(response, 404, false, "not found");
}

}  // namespace sh::fw::web
