// SDO server (CiA 301 7.2.4): expedited and segmented upload and download of the object
// dictionary, with the CiA abort codes. Block transfer is not offered: a block request is
// answered with abort 0x05040001 and the client falls back to segmented transfer.
//
// Requests arrive on the COB-ID of 0x1200 sub 1 (0x600 + node id), responses leave on 0x1200
// sub 2 (0x580 + node id). One transfer at a time (a new initiate replaces a transfer in
// progress, as the client has evidently given it up). A segmented transfer that sees no request
// for `timeout_ns` is aborted with 0x05040000 (Poll).
//
// Pure and thread-free: the caller passes received frames and the time, and sends what comes
// back. No heap: a transfer's data lives in a fixed buffer (the largest value is a string of
// kOdStringCapacity bytes).
#pragma once

#include <cstdint>

#include "firmware/canopen/object_dictionary.hpp"
#include "hal/can.hpp"

namespace sh::canopen {

inline constexpr int64_t kSdoDefaultTimeoutNs = 1'000'000'000;  // 1 s between segments
inline constexpr size_t kSdoBufferBytes = 64;                   // >= kOdStringCapacity

struct SdoCounters {
  uint64_t requests = 0;
  uint64_t aborts_sent = 0;      // by this server
  uint64_t aborts_received = 0;  // from the client
  uint64_t timeouts = 0;
};

class SdoServer {
 public:
  explicit SdoServer(ObjectDictionary* od, int64_t timeout_ns = kSdoDefaultTimeoutNs)
      : od_(od), timeout_ns_(timeout_ns) {}

  // true: `request` was an SDO request to this node and *response is the frame to send. false:
  // not an SDO request to this node, or an abort from the client (which needs no answer).
  bool Handle(const hal::CanFrame& request, int64_t now_ns, hal::CanFrame* response);
  // Aborts a segmented transfer that timed out: true with *response the abort frame.
  bool Poll(int64_t now_ns, hal::CanFrame* response);
  // Drops a transfer in progress (NMT reset, stop).
  void Reset() { state_ = State::kIdle; }

  bool busy() const { return state_ != State::kIdle; }
  const SdoCounters& counters() const { return counters_; }

 private:
  enum class State : uint8_t { kIdle, kDownloading, kUploading };

  void Abort(uint16_t index, uint8_t sub, SdoAbort code, hal::CanFrame* response);
  void InitiateDownload(const uint8_t* d, int64_t now_ns, hal::CanFrame* response);
  void DownloadSegment(const uint8_t* d, int64_t now_ns, hal::CanFrame* response);
  void InitiateUpload(const uint8_t* d, int64_t now_ns, hal::CanFrame* response);
  void UploadSegment(const uint8_t* d, int64_t now_ns, hal::CanFrame* response);
  hal::CanFrame MakeResponse() const;

  ObjectDictionary* od_;
  int64_t timeout_ns_;
  State state_ = State::kIdle;
  uint16_t index_ = 0;
  uint8_t sub_ = 0;
  uint8_t toggle_ = 0;       // expected toggle bit of the next segment
  bool size_known_ = false;  // download: the client indicated the size
  size_t size_ = 0;          // download: indicated size; upload: bytes to send
  size_t position_ = 0;      // bytes received / sent so far
  int64_t last_ns_ = 0;      // time of the last request of the transfer
  uint8_t buffer_[kSdoBufferBytes] = {};
  SdoCounters counters_;
};

}  // namespace sh::canopen
