#include "firmware/web/web_auth.hpp"

#include <crypt.h>
#include <sys/random.h>

#include <cstdio>
#include <cstring>

#include "tables/input_file.hpp"

namespace sh::fw::web {

bool ConstantTimeEquals(const char* a, size_t a_bytes, const char* b, size_t b_bytes) {
  unsigned diff = a_bytes == b_bytes ? 0u : 1u;
  const size_t n = a_bytes < b_bytes ? a_bytes : b_bytes;
  for (size_t i = 0; i < n; ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

bool RandomHex(char* out, size_t bytes) {
  unsigned char raw[64];
  if (bytes > sizeof(raw)) return false;
  if (getrandom(raw, bytes, 0) != static_cast<ssize_t>(bytes)) return false;
  static const char kHex[] = "0123456789abcdef";
  for (size_t i = 0; i < bytes; ++i) {
    out[2 * i] = kHex[raw[i] >> 4];
    out[2 * i + 1] = kHex[raw[i] & 15];
  }
  out[2 * bytes] = '\0';
  return true;
}

Result<std::string> ReadPasswordHashFile(const char* path) {
  char text[1024] = {};
  size_t n = 0;
  SH_RETURN_IF_ERROR(ReadInputFile(path, "http_password_file", text, sizeof(text) - 1, &n));
  size_t end = 0;
  while (end < n && text[end] != '\n' && text[end] != '\r') ++end;
  return std::string(text, end);
}

WebAuth::WebAuth() = default;
WebAuth::~WebAuth() = default;

Status WebAuth::Configure(const char* password, const char* hash) {
  mode_ = Mode::kReadOnly;
  secret_.clear();
  if (password != nullptr && password[0] != '\0') {
    mode_ = Mode::kPlain;
    secret_ = password;
  } else if (hash != nullptr && hash[0] != '\0') {
    if (hash[0] != '$' || std::strchr(hash + 1, '$') == nullptr) {
      return Status::Error(StatusCode::kInvalidArgument,
                           "key 'http_password_file': the file holds no crypt(3) hash ($6$..., "
                           "as mkpasswd -m sha-512 or openssl passwd -6 write)");
    }
    mode_ = Mode::kHash;
    secret_ = hash;
    crypt_ = std::make_unique<crypt_data>();  // 32 KiB of the hash functions' state
  }
  return Status::Ok();
}

bool WebAuth::PasswordMatches(const char* password, size_t bytes) {
  if (mode_ == Mode::kPlain) {
    return ConstantTimeEquals(password, bytes, secret_.data(), secret_.size());
  }
  if (std::strlen(password) != bytes) return false;  // a NUL inside: not what was hashed
  std::memset(crypt_.get(), 0, sizeof(crypt_data));
  const char* hashed = crypt_r(password, secret_.c_str(), crypt_.get());
  if (hashed == nullptr || hashed[0] == '*') return false;
  return ConstantTimeEquals(hashed, std::strlen(hashed), secret_.data(), secret_.size());
}

Result<LoginTokens> WebAuth::Login(const char* password, size_t bytes, int64_t now_ns) {
  if (mode_ == Mode::kReadOnly) {
    return Status::Error(StatusCode::kFailedPrecondition,
                         "no password is configured: the page is read-only");
  }
  if (now_ns < pause_until_ns_) {
    return Status::Error(StatusCode::kUnavailable, "a wrong password was given: wait a second");
  }
  if (bytes > kMaxPasswordBytes || !PasswordMatches(password, bytes)) {
    pause_until_ns_ = now_ns + kLoginPauseNs;
    return Status::Error(StatusCode::kInvalidArgument, "wrong password");
  }
  // A free slot, or the one used longest ago.
  Session* slot = &sessions_[0];
  for (Session& s : sessions_) {
    if (!s.live || now_ns - s.last_used_ns > kSessionIdleNs) {
      slot = &s;
      break;
    }
    if (s.last_used_ns < slot->last_used_ns) slot = &s;
  }
  if (!RandomHex(slot->token, kTokenHexChars / 2) || !RandomHex(slot->csrf, kTokenHexChars / 2)) {
    slot->live = false;
    return Status::Error(StatusCode::kUnavailable, "no random numbers for a session");
  }
  slot->live = true;
  slot->last_used_ns = now_ns;
  return LoginTokens{slot->token, slot->csrf};
}

WebAuth::Session* WebAuth::Find(const std::string& token, int64_t now_ns) {
  if (token.size() != kTokenHexChars) return nullptr;
  for (Session& s : sessions_) {
    if (!s.live) continue;
    if (now_ns - s.last_used_ns > kSessionIdleNs) {
      s.live = false;
      continue;
    }
    if (ConstantTimeEquals(s.token, kTokenHexChars, token.data(), token.size())) return &s;
  }
  return nullptr;
}

bool WebAuth::Authenticated(const std::string& session, int64_t now_ns, std::string* csrf) {
  Session* s = Find(session, now_ns);
  if (s == nullptr) return false;
  s->last_used_ns = now_ns;
  if (csrf != nullptr) *csrf = s->csrf;
  return true;
}

bool WebAuth::Authorised(const std::string& session, const char* csrf_header, int64_t now_ns) {
  Session* s = Find(session, now_ns);
  if (s == nullptr || csrf_header == nullptr) return false;
  if (!ConstantTimeEquals(s->csrf, kTokenHexChars, csrf_header, std::strlen(csrf_header))) {
    return false;
  }
  s->last_used_ns = now_ns;
  return true;
}

void WebAuth::Logout(const std::string& session) {
  if (session.size() != kTokenHexChars) return;
  for (Session& s : sessions_) {
    if (s.live && ConstantTimeEquals(s.token, kTokenHexChars, session.data(), session.size())) {
      s.live = false;
    }
  }
}

}  // namespace sh::fw::web
