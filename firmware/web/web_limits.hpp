// The limits of the commissioning web server: what a client may ask of it, and so how much
// memory and time a slow or hostile one can take (docs/web.md, Limits).
#pragma once

#include <cstddef>
#include <cstdint>

namespace sh::fw::web {

// Connections served at once, and from one address; further ones are closed on accept.
inline constexpr unsigned kMaxConnections = 32;
inline constexpr unsigned kMaxConnectionsPerAddress = 16;
// A connection that sends nothing this long is closed (slow clients, slowloris).
inline constexpr unsigned kConnectionTimeoutS = 10;
// Memory of one connection for its request line and headers; a larger header is refused (431).
inline constexpr size_t kConnectionMemoryBytes = size_t{16} * 1024;
// Request bodies (login, settings); a larger one is refused (413).
inline constexpr size_t kMaxBodyBytes = size_t{16} * 1024;
// Requests the server answers per second over all clients, with a burst; others get 429.
inline constexpr uint32_t kRequestsPerSecond = 100;
inline constexpr uint32_t kRequestBurst = 200;
// Logins: sessions held at once, idle time before a session ends, and the pause after a wrong
// password during which every login is refused (bounds guessing to one try per pause).
inline constexpr size_t kMaxSessions = 8;
inline constexpr int64_t kSessionIdleNs = int64_t{30} * 60 * 1'000'000'000;
inline constexpr int64_t kLoginPauseNs = int64_t{1'000'000'000};
// Pairs one request may ask to record, and the largest recording archive served (a pair of
// kMaxImageWidth x kMaxImageHeight PGMs with its result is 2.6 MB).
inline constexpr int kMaxRecordRequest = 100;
// How long a chessboard capture waits for its pair (the trigger's capture and recognition); the
// server thread answers no other request meanwhile.
inline constexpr int kCaptureWaitMs = 3000;
inline constexpr size_t kMaxArchiveBytes = size_t{4} * 1024 * 1024;
// Answers above kLargeResponseBytes (the archives) count against kMaxLargeResponseBytes until
// sent; one that would pass it is refused (503) for the client to try again. With the connection
// limit this bounds the server's memory.
inline constexpr size_t kLargeResponseBytes = size_t{1} * 1024 * 1024;
inline constexpr size_t kMaxLargeResponseBytes = size_t{8} * 1024 * 1024;
// The live images: the largest side served (larger frames are halved until they fit).
inline constexpr int kLiveMaxWidth = 640;
inline constexpr int kLiveMaxHeight = 512;
// Nice value of the server thread: below the firmware's threads.
inline constexpr int kServerNice = 10;

}  // namespace sh::fw::web
