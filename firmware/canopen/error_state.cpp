#include "firmware/canopen/error_state.hpp"

#include "firmware/canopen/emcy.hpp"
#include "firmware/canopen/od_table.hpp"

namespace sh::canopen {
namespace {

int BitIndex(uint32_t bit) {
  for (int i = 0; i < 32; ++i) {
    if (bit == (1u << i)) return i;
  }
  return -1;
}

}  // namespace

uint8_t ErrorState::RegisterOf(uint32_t conditions) const {
  uint8_t reg = 0;
  for (int i = 0; i < 32; ++i) {
    if (conditions & (1u << i)) reg |= protocol::ErrorRegisterFor(codes_[i]);
  }
  return reg;
}

void ErrorState::Publish() { (void)od_->Set(kIdxErrorRegister, 0, error_register()); }

void ErrorState::Push(uint16_t code, uint32_t detail) {
  const uint8_t count = static_cast<uint8_t>(od_->Get(kIdxErrorHistory, 0));
  for (uint8_t s = kErrorHistoryDepth; s > 1; --s) {
    (void)od_->Set(kIdxErrorHistory, s, od_->Get(kIdxErrorHistory, static_cast<uint8_t>(s - 1)));
  }
  (void)od_->Set(kIdxErrorHistory, 1, (detail & 0xFFFFu) << 16 | code);
  (void)od_->Set(kIdxErrorHistory, 0, count < kErrorHistoryDepth ? count + 1 : count);
}

EmcyMessage ErrorState::Raise(uint32_t bit, uint16_t code, uint32_t detail) {
  const int i = BitIndex(bit);
  if (i >= 0) {
    active_ |= bit;
    codes_[i] = code;
  }
  Publish();
  Push(code, detail);
  EmcyMessage m;
  m.code = code;
  m.error_register = error_register();
  m.detail = detail;
  return m;
}

bool ErrorState::Clear(uint32_t bit, EmcyMessage* reset) { return ClearAll(bit, reset); }

bool ErrorState::ClearAll(uint32_t bits, EmcyMessage* reset) {
  if ((active_ & bits) == 0) return false;
  active_ &= ~bits;
  Publish();
  *reset = EmcyMessage();
  reset->error_register = error_register();
  return true;
}

void ErrorState::Event(uint16_t code, uint32_t detail, EmcyMessage* error, EmcyMessage* reset) {
  Push(code, detail);
  error->code = code;
  error->error_register = static_cast<uint8_t>(error_register() | protocol::ErrorRegisterFor(code));
  error->detail = detail;
  *reset = EmcyMessage();
  reset->error_register = error_register();
  Publish();
}

SdoAbort ErrorState::WriteHistoryCount(uint32_t value) {
  if (value != 0) return SdoAbort::kInvalidValue;
  for (uint8_t s = 1; s <= kErrorHistoryDepth; ++s) (void)od_->Set(kIdxErrorHistory, s, 0);
  return SdoAbort::kNone;
}

}  // namespace sh::canopen
