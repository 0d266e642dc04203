// Logins of the commissioning page: the password (http_password, or a crypt(3) hash in
// http_password_file), sessions held in a fixed table, a CSRF token per session that every
// request that changes something must repeat in a header, and a pause after a wrong password.
// Without a password the page is read-only: no login succeeds. Used from the server thread only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "firmware/web/web_limits.hpp"
#include "recog/base/status.hpp"

struct crypt_data;

namespace sh::fw::web {

inline constexpr size_t kTokenHexChars = 32;  // 128 random bits
inline constexpr size_t kMaxPasswordBytes = 256;

struct LoginTokens {
  std::string session;  // the cookie's value
  std::string csrf;     // to repeat in the X-CSRF-Token header
};

class WebAuth {
 public:
  WebAuth();
  ~WebAuth();
  WebAuth(const WebAuth&) = delete;
  WebAuth& operator=(const WebAuth&) = delete;

  // `password` in plain text or `hash` (a crypt(3) string: $6$..., $5$..., $y$...); both empty:
  // read-only. A hash that is not one is an error.
  Status Configure(const char* password, const char* hash);
  bool enabled() const { return mode_ != Mode::kReadOnly; }

  // A new session for the right password. kInvalidArgument for a wrong one (and every login
  // is refused for kLoginPauseNs after it, kUnavailable), kFailedPrecondition when read-only.
  Result<LoginTokens> Login(const char* password, size_t bytes, int64_t now_ns);
  // The session's CSRF token if `session` is a live session (its idle time restarts), else
  // false.
  bool Authenticated(const std::string& session, int64_t now_ns, std::string* csrf);
  // A live session whose CSRF token is `csrf_header`.
  bool Authorised(const std::string& session, const char* csrf_header, int64_t now_ns);
  void Logout(const std::string& session);

 private:
  enum class Mode : uint8_t { kReadOnly, kPlain, kHash };
  struct Session {
    char token[kTokenHexChars + 1] = {};
    char csrf[kTokenHexChars + 1] = {};
    int64_t last_used_ns = 0;
    bool live = false;
  };
  bool PasswordMatches(const char* password, size_t bytes);
  Session* Find(const std::string& token, int64_t now_ns);

  Mode mode_ = Mode::kReadOnly;
  std::string secret_;  // the password or its hash
  std::unique_ptr<crypt_data> crypt_;
  Session sessions_[kMaxSessions];
  int64_t pause_until_ns_ = 0;
};

// Equal strings, in a time that depends on their lengths only.
bool ConstantTimeEquals(const char* a, size_t a_bytes, const char* b, size_t b_bytes);

// `bytes` random bytes as lower-case hex into out (2 * bytes + 1 chars); false if the kernel's
// generator failed.
bool RandomHex(char* out, size_t bytes);

// Reads the password hash of http_password_file: its first line, trimmed.
Result<std::string> ReadPasswordHashFile(const char* path);

}  // namespace sh::fw::web
