#include "firmware/canopen/sdo_server.hpp"

#include <cstring>

#include "firmware/le_bytes.hpp"

namespace sh::canopen {
namespace {

using protocol::GetU16;
using protocol::GetU32;
using protocol::PutU32;

// Command specifiers (byte 0, bits 7..5) of client requests and server responses.
constexpr uint8_t kCcsDownloadSegment = 0;
constexpr uint8_t kCcsInitiateDownload = 1;
constexpr uint8_t kCcsInitiateUpload = 2;
constexpr uint8_t kCcsUploadSegment = 3;
constexpr uint8_t kCsAbort = 4;
constexpr uint8_t kCcsBlockUpload = 5;
constexpr uint8_t kCcsBlockDownload = 6;

constexpr uint8_t kScsUploadSegment = 0 << 5;
constexpr uint8_t kScsDownloadSegment = 1 << 5;
constexpr uint8_t kScsInitiateUpload = 2 << 5;
constexpr uint8_t kScsInitiateDownload = 3 << 5;
constexpr uint8_t kScsAbort = 4 << 5;

constexpr size_t kSegmentBytes = 7;

}  // namespace

hal::CanFrame SdoServer::MakeResponse() const {
  hal::CanFrame f;
  f.id = od_->Get(kIdxSdoServer, 2) & hal::kCanStandardIdMax;
  f.len = 8;
  return f;
}

void SdoServer::Abort(uint16_t index, uint8_t sub, SdoAbort code, hal::CanFrame* response) {
  state_ = State::kIdle;
  *response = MakeResponse();
  response->data[0] = kScsAbort;
  response->data[1] = static_cast<uint8_t>(index);
  response->data[2] = static_cast<uint8_t>(index >> 8);
  response->data[3] = sub;
  PutU32(&response->data[4], static_cast<uint32_t>(code));
  ++counters_.aborts_sent;
}

bool SdoServer::Handle(const hal::CanFrame& request, int64_t now_ns, hal::CanFrame* response) {
  const uint32_t rx_id = od_->Get(kIdxSdoServer, 1);
  if (request.extended || request.rtr || request.error ||
      request.id != (rx_id & hal::kCanStandardIdMax)) {
    return false;
  }
  ++counters_.requests;
  const uint8_t* d = request.data;
  const uint8_t cs = d[0] >> 5;
  if (cs == kCsAbort) {
    ++counters_.aborts_received;
    state_ = State::kIdle;
    return false;
  }
  if (request.len != 8) {
    // SDO frames always carry 8 bytes; a shorter one cannot be interpreted safely.
    Abort(request.len >= 3 ? GetU16(&d[1]) : 0, request.len >= 4 ? d[3] : 0,
          SdoAbort::kCommandSpecifier, response);
    return true;
  }
  switch (cs) {
    case kCcsInitiateDownload:
      InitiateDownload(d, now_ns, response);
      return true;
    case kCcsDownloadSegment:
      DownloadSegment(d, now_ns, response);
      return true;
    case kCcsInitiateUpload:
      InitiateUpload(d, now_ns, response);
      return true;
    case kCcsUploadSegment:
      UploadSegment(d, now_ns, response);
      return true;
    case kCcsBlockUpload:
    case kCcsBlockDownload:
    default:
      Abort(GetU16(&d[1]), d[3], SdoAbort::kCommandSpecifier, response);
      return true;
  }
}

bool SdoServer::Poll(int64_t now_ns, hal::CanFrame* response) {
  if (state_ == State::kIdle || now_ns - last_ns_ < timeout_ns_) return false;
  ++counters_.timeouts;
  Abort(index_, sub_, SdoAbort::kTimeout, response);
  return true;
}

void SdoServer::InitiateDownload(const uint8_t* d, int64_t now_ns, hal::CanFrame* response) {
  state_ = State::kIdle;  // a new initiate replaces any transfer in progress
  const uint16_t index = GetU16(&d[1]);
  const uint8_t sub = d[3];
  const bool expedited = (d[0] & 0x02) != 0;
  const bool size_indicated = (d[0] & 0x01) != 0;
  const OdEntry* e = nullptr;
  const SdoAbort found = od_->Lookup(index, sub, &e);
  if (found != SdoAbort::kNone) return Abort(index, sub, found, response);
  if (!Writable(e->access())) return Abort(index, sub, SdoAbort::kReadOnly, response);

  if (expedited) {
    size_t n = 4;
    if (size_indicated) {
      n = 4 - ((d[0] >> 2) & 0x03);
    } else if (e->type() != DataType::kVisibleString) {
      n = DataTypeSize(e->type());  // size unspecified: the object's own size
    }
    const SdoAbort written = od_->Write(index, sub, &d[4], n);
    if (written != SdoAbort::kNone) return Abort(index, sub, written, response);
    *response = MakeResponse();
    response->data[0] = kScsInitiateDownload;
    std::memcpy(&response->data[1], &d[1], 3);
    return;
  }
  size_known_ = size_indicated;
  size_ = size_indicated ? GetU32(&d[4]) : 0;
  if (size_known_ && size_ > kSdoBufferBytes) {
    return Abort(index, sub, SdoAbort::kLengthTooHigh, response);
  }
  state_ = State::kDownloading;
  index_ = index;
  sub_ = sub;
  toggle_ = 0;
  position_ = 0;
  last_ns_ = now_ns;
  *response = MakeResponse();
  response->data[0] = kScsInitiateDownload;
  std::memcpy(&response->data[1], &d[1], 3);
}

void SdoServer::DownloadSegment(const uint8_t* d, int64_t now_ns, hal::CanFrame* response) {
  if (state_ != State::kDownloading) {
    return Abort(index_, sub_, SdoAbort::kCommandSpecifier, response);
  }
  const uint8_t toggle = (d[0] >> 4) & 0x01;
  if (toggle != toggle_) return Abort(index_, sub_, SdoAbort::kToggleBit, response);
  const size_t n = kSegmentBytes - ((d[0] >> 1) & 0x07);
  const bool last = (d[0] & 0x01) != 0;
  if (position_ + n > kSdoBufferBytes || (size_known_ && position_ + n > size_)) {
    return Abort(index_, sub_, SdoAbort::kLengthTooHigh, response);
  }
  std::memcpy(&buffer_[position_], &d[1], n);
  position_ += n;
  last_ns_ = now_ns;
  if (last) {
    if (size_known_ && position_ != size_) {
      return Abort(index_, sub_, SdoAbort::kLengthTooLow, response);
    }
    const SdoAbort written = od_->Write(index_, sub_, buffer_, position_);
    if (written != SdoAbort::kNone) return Abort(index_, sub_, written, response);
    state_ = State::kIdle;
  }
  *response = MakeResponse();
  response->data[0] = static_cast<uint8_t>(kScsDownloadSegment | toggle << 4);
  toggle_ ^= 1;
}

void SdoServer::InitiateUpload(const uint8_t* d, int64_t now_ns, hal::CanFrame* response) {
  state_ = State::kIdle;
  const uint16_t index = GetU16(&d[1]);
  const uint8_t sub = d[3];
  size_t n = 0;
  const SdoAbort read = od_->Read(index, sub, buffer_, sizeof(buffer_), &n);
  if (read != SdoAbort::kNone) return Abort(index, sub, read, response);
  *response = MakeResponse();
  std::memcpy(&response->data[1], &d[1], 3);
  if (n <= 4 && n > 0) {
    // Expedited: e = 1, s = 1, n = number of bytes in 4..7 that hold no data.
    response->data[0] = static_cast<uint8_t>(kScsInitiateUpload | (4 - n) << 2 | 0x03);
    std::memcpy(&response->data[4], buffer_, n);
    return;
  }
  // Segmented (also an empty string: size 0, one empty last segment).
  response->data[0] = kScsInitiateUpload | 0x01;
  PutU32(&response->data[4], static_cast<uint32_t>(n));
  state_ = State::kUploading;
  index_ = index;
  sub_ = sub;
  toggle_ = 0;
  size_ = n;
  position_ = 0;
  last_ns_ = now_ns;
}

void SdoServer::UploadSegment(const uint8_t* d, int64_t now_ns, hal::CanFrame* response) {
  if (state_ != State::kUploading) {
    return Abort(index_, sub_, SdoAbort::kCommandSpecifier, response);
  }
  const uint8_t toggle = (d[0] >> 4) & 0x01;
  if (toggle != toggle_) return Abort(index_, sub_, SdoAbort::kToggleBit, response);
  size_t n = size_ - position_;
  if (n > kSegmentBytes) n = kSegmentBytes;
  const bool last = position_ + n == size_;
  *response = MakeResponse();
  response->data[0] = static_cast<uint8_t>(kScsUploadSegment | toggle << 4 |
                                           (kSegmentBytes - n) << 1 | (last ? 1 : 0));
  std::memcpy(&response->data[1], &buffer_[position_], n);
  position_ += n;
  toggle_ ^= 1;
  last_ns_ = now_ns;
  if (last) state_ = State::kIdle;
}

}  // namespace sh::canopen
