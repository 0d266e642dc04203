#include "firmware/web/web_service.hpp"

#include <string>

#include "tables/input_file.hpp"

#include "firmware/web/core_target.hpp"
#include "firmware/web/http_server.hpp"
#include "firmware/web/live_snapshot.hpp"
#include "firmware/web/web_app.hpp"
#include "firmware/web/web_auth.hpp"
#include "firmware/web/web_settings.hpp"

namespace sh::fw::web {

class WebServiceParts {
 public:
  LiveSnapshot snapshot;
  WebAuth auth;
  std::unique_ptr<WebSettings> settings;
  std::unique_ptr<CoreTarget> target;
  std::unique_ptr<WebApp> app;
  HttpServer server;
  StereoCalibration calibration;
  std::string record_dir, output_frame;
  std::string tls_cert_pem, tls_key_pem;  // the server reads them until it stops
  PairCapture capture;                    // the calibration helper's pairs
};

namespace {

// A PEM file of the TLS keys: a regular file of at most this size (a certificate chain).
constexpr size_t kMaxPemBytes = size_t{64} * 1024;

Result<std::string> ReadPemFile(const char* path, const char* key) {
  std::string text;
  SH_RETURN_IF_ERROR(ReadInputFile(std::string(path), key, kMaxPemBytes, &text));
  if (text.find("-----BEGIN ") == std::string::npos) {
    return Status::Error(StatusCode::kInvalidArgument, "key '%s': %s holds no PEM block", key,
                         path);
  }
  return text;
}

// The certificate and key of HTTPS: both keys or neither.
Status LoadTlsKeys(const FwConfig& config, WebServiceParts* p, HttpServerConfig* sc) {
  const bool cert = config.http_tls_cert[0] != '\0', key = config.http_tls_key[0] != '\0';
  if (!cert && !key) return Status::Ok();
  if (cert != key) {
    return Status::Error(
        StatusCode::kInvalidArgument, "key '%s' is set but '%s' is not: HTTPS needs both",
        cert ? "http_tls_cert" : "http_tls_key", cert ? "http_tls_key" : "http_tls_cert");
  }
  SH_ASSIGN_OR_RETURN(p->tls_cert_pem, ReadPemFile(config.http_tls_cert, "http_tls_cert"));
  SH_ASSIGN_OR_RETURN(p->tls_key_pem, ReadPemFile(config.http_tls_key, "http_tls_key"));
  sc->tls_cert_pem = p->tls_cert_pem.c_str();
  sc->tls_key_pem = p->tls_key_pem.c_str();
  return Status::Ok();
}

}  // namespace

WebService::WebService() = default;
WebService::~WebService() { Stop(); }

Result<CoreObserver*> WebService::Prepare(const FwConfig& config,
                                          const RigidTransform& out_T_camera) {
  if (config.http_bind[0] == '\0') return static_cast<CoreObserver*>(nullptr);
  parts_ = std::make_unique<WebServiceParts>();
  SH_RETURN_IF_ERROR(parts_->snapshot.Init(out_T_camera.Inverse()));
  parts_->snapshot.SetCapture(&parts_->capture);
  return static_cast<CoreObserver*>(&parts_->snapshot);
}

Status WebService::Start(const FwConfig& config, const Running& running, std::FILE* announce) {
  if (parts_ == nullptr) return Status::Ok();
  WebServiceParts& p = *parts_;
  std::string hash;
  if (config.http_password_file[0] != '\0') {
    SH_ASSIGN_OR_RETURN(hash, ReadPasswordHashFile(config.http_password_file));
  }
  SH_RETURN_IF_ERROR(p.auth.Configure(config.http_password, hash.c_str()));
  HttpServerConfig sc;
  sc.bind_address = config.http_bind;
  sc.port = static_cast<uint16_t>(config.http_port);
  SH_RETURN_IF_ERROR(LoadTlsKeys(config, &p, &sc));
  p.settings = std::make_unique<WebSettings>(config, running.config_path);
  p.target =
      std::make_unique<CoreTarget>(running.core, running.recorder, running.can, running.camera);
  p.record_dir = config.record_dir;
  p.output_frame = running.output_frame;
  WebAppConfig ac;
  ac.record_dir = p.record_dir.c_str();
  ac.output_frame = p.output_frame.c_str();
  ac.https = sc.tls_cert_pem != nullptr;
  ac.capture = &p.capture;
  if (running.calibration != nullptr) {
    p.calibration = *running.calibration;
    ac.calibration = &p.calibration;
  }
  if (running.left_T_volume != nullptr) {
    ac.volume = true;
    ac.left_T_volume = *running.left_T_volume;
    for (int k = 0; k < 3; ++k) {
      ac.volume_min_mm[k] = config.volume_min_mm[k];
      ac.volume_max_mm[k] = config.volume_max_mm[k];
    }
  }
  p.app = std::make_unique<WebApp>(ac, &p.auth, p.settings.get(), &p.snapshot, p.target.get());
  SH_RETURN_IF_ERROR(p.server.Start(sc, p.app.get()));
  std::fprintf(announce, "HTTP_PORT=%u\n", p.server.port());
  if (p.server.https()) std::fprintf(announce, "HTTP_SCHEME=https\n");
  std::fflush(announce);
  return Status::Ok();
}

void WebService::Stop() {
  if (parts_ != nullptr) parts_->server.Stop();
}

}  // namespace sh::fw::web
