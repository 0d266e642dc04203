// The commissioning page's logins: plain and hashed passwords, sessions, CSRF tokens, the pause
// after a wrong password, read-only without a password; and the request rate limit.
#include "firmware/web/web_auth.hpp"

#include <crypt.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <memory>
#include <string>

#include "firmware/web/web_app.hpp"
#include "tests/support/temp_dir.hpp"

namespace sh::fw::web {
namespace {

constexpr int64_t kSecond = 1'000'000'000;

Result<LoginTokens> LoginWith(WebAuth* auth, const char* password, int64_t now_ns) {
  return auth->Login(password, std::strlen(password), now_ns);
}

TEST(WebAuth, WithoutPasswordEveryLoginIsRefused) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("", "").ok());
  EXPECT_FALSE(auth.enabled());
  const Result<LoginTokens> login = LoginWith(&auth, "", kSecond);
  ASSERT_FALSE(login.ok());
  EXPECT_EQ(login.status().code(), StatusCode::kFailedPrecondition);
}

TEST(WebAuth, RightPasswordGivesSessionAndToken) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  const Result<LoginTokens> login = LoginWith(&auth, "secret", kSecond);
  ASSERT_TRUE(login.ok()) << login.status().message();
  EXPECT_EQ(login->session.size(), kTokenHexChars);
  EXPECT_EQ(login->csrf.size(), kTokenHexChars);
  EXPECT_NE(login->session, login->csrf);
  std::string csrf;
  EXPECT_TRUE(auth.Authenticated(login->session, 2 * kSecond, &csrf));
  EXPECT_EQ(csrf, login->csrf);
  EXPECT_TRUE(auth.Authorised(login->session, login->csrf.c_str(), 2 * kSecond));
}

TEST(WebAuth, SessionWithoutItsTokenIsNotAuthorised) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  const Result<LoginTokens> login = LoginWith(&auth, "secret", kSecond);
  ASSERT_TRUE(login.ok());
  EXPECT_FALSE(auth.Authorised(login->session, nullptr, kSecond));
  EXPECT_FALSE(auth.Authorised(login->session, "", kSecond));
  EXPECT_FALSE(auth.Authorised(login->session, login->session.c_str(), kSecond));
  EXPECT_FALSE(auth.Authorised("", login->csrf.c_str(), kSecond));
  std::string other = login->session;
  other[0] = other[0] == 'a' ? 'b' : 'a';
  EXPECT_FALSE(auth.Authorised(other, login->csrf.c_str(), kSecond));
}

TEST(WebAuth, WrongPasswordPausesEveryLogin) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  const Result<LoginTokens> wrong = LoginWith(&auth, "secreT", kSecond);
  ASSERT_FALSE(wrong.ok());
  EXPECT_EQ(wrong.status().code(), StatusCode::kInvalidArgument);
  // Within the pause even the right password is refused: guessing gets one try per pause.
  const Result<LoginTokens> paused = LoginWith(&auth, "secret", kSecond + kLoginPauseNs / 2);
  ASSERT_FALSE(paused.ok());
  EXPECT_EQ(paused.status().code(), StatusCode::kUnavailable);
  EXPECT_TRUE(LoginWith(&auth, "secret", kSecond + kLoginPauseNs).ok());
}

TEST(WebAuth, PrefixOfThePasswordIsWrong) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  EXPECT_FALSE(LoginWith(&auth, "secre", kSecond).ok());
  EXPECT_FALSE(LoginWith(&auth, "secret2", 3 * kSecond).ok());
}

TEST(WebAuth, IdleSessionEnds) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  const Result<LoginTokens> login = LoginWith(&auth, "secret", kSecond);
  ASSERT_TRUE(login.ok());
  EXPECT_FALSE(auth.Authenticated(login->session, kSecond + kSessionIdleNs + 1, nullptr));
}

TEST(WebAuth, LogoutEndsTheSession) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  const Result<LoginTokens> login = LoginWith(&auth, "secret", kSecond);
  ASSERT_TRUE(login.ok());
  auth.Logout(login->session);
  EXPECT_FALSE(auth.Authenticated(login->session, kSecond, nullptr));
}

TEST(WebAuth, SessionsBeyondTheTableReplaceTheOldest) {
  WebAuth auth;
  ASSERT_TRUE(auth.Configure("secret", "").ok());
  std::string first;
  for (size_t i = 0; i <= kMaxSessions; ++i) {
    const Result<LoginTokens> login = LoginWith(&auth, "secret", kSecond * int64_t(i + 1));
    ASSERT_TRUE(login.ok());
    if (i == 0) first = login->session;
  }
  EXPECT_FALSE(auth.Authenticated(first, kSecond * int64_t(kMaxSessions + 2), nullptr));
}

TEST(WebAuth, HashedPasswordFromFile) {
  // A SHA-512 crypt hash made here, as `mkpasswd -m sha-512` writes it.
  auto data = std::make_unique<crypt_data>();
  const char* hash = crypt_r("pa55 word", "$6$web.test.salt$", data.get());
  ASSERT_NE(hash, nullptr);
  ASSERT_EQ(hash[0], '$');
  testing::TempDir dir("web_auth");
  const std::string path = dir.path() + "/password";
  std::ofstream(path) << hash << "\n";
  const Result<std::string> read = ReadPasswordHashFile(path.c_str());
  ASSERT_TRUE(read.ok()) << read.status().message();
  EXPECT_EQ(*read, hash);

  WebAuth auth;
  ASSERT_TRUE(auth.Configure("", read->c_str()).ok());
  EXPECT_TRUE(auth.enabled());
  EXPECT_FALSE(LoginWith(&auth, "pa55 wor", kSecond).ok());
  EXPECT_TRUE(LoginWith(&auth, "pa55 word", kSecond + kLoginPauseNs).ok());
}

TEST(WebAuth, FileWithoutHashIsAnError) {
  WebAuth auth;
  const Status s = auth.Configure("", "secret");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(std::strstr(s.message(), "http_password_file"), nullptr) << s.message();
}

TEST(RateLimit, BurstThenRate) {
  RateLimit limit(10, 5);
  int taken = 0;
  for (int i = 0; i < 20; ++i) taken += limit.Take(kSecond) ? 1 : 0;
  EXPECT_EQ(taken, 5);
  // A tenth of a second later one more request fits at 10 per second.
  EXPECT_TRUE(limit.Take(kSecond + kSecond / 10));
  EXPECT_FALSE(limit.Take(kSecond + kSecond / 10));
}

TEST(ConstantTimeEquals, ComparesContentAndLength) {
  EXPECT_TRUE(ConstantTimeEquals("abc", 3, "abc", 3));
  EXPECT_FALSE(ConstantTimeEquals("abc", 3, "abd", 3));
  EXPECT_FALSE(ConstantTimeEquals("abc", 3, "abcd", 4));
  EXPECT_FALSE(ConstantTimeEquals("", 0, "a", 1));
}

}  // namespace
}  // namespace sh::fw::web
