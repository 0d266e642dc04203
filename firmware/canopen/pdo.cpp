#include "firmware/canopen/pdo.hpp"

namespace sh::canopen {
namespace {

struct MappedObject {
  uint16_t index;
  uint8_t sub;
  uint8_t bytes;
};

MappedObject Mapped(const ObjectDictionary& od, uint16_t map_index, uint8_t k) {
  const uint32_t m = od.Get(map_index, k);
  return {static_cast<uint16_t>(m >> 16), static_cast<uint8_t>(m >> 8),
          static_cast<uint8_t>((m & 0xFF) / 8)};
}

size_t MappingLength(const ObjectDictionary& od, uint16_t map_index) {
  size_t n = 0;
  const uint8_t count = static_cast<uint8_t>(od.Get(map_index, 0));
  for (uint8_t k = 1; k <= count; ++k) n += Mapped(od, map_index, k).bytes;
  return n;
}

// CiA 301 table 5: identifiers no PDO may use.
bool Restricted(uint32_t id) {
  return id <= 0x07F || (id >= 0x101 && id <= 0x180) || (id >= 0x581 && id <= 0x5FF) ||
         (id >= 0x601 && id <= 0x67F) || (id >= 0x6E0 && id <= 0x6FF) || id >= 0x701;
}

}  // namespace

uint32_t TpdoCobId(const ObjectDictionary& od, int n) {
  return od.Get(static_cast<uint16_t>(kIdxTpdoComm + n), 1);
}
uint32_t RpdoCobId(const ObjectDictionary& od, int n) {
  return od.Get(static_cast<uint16_t>(kIdxRpdoComm + n), 1);
}
size_t TpdoLength(const ObjectDictionary& od, int n) {
  return MappingLength(od, static_cast<uint16_t>(kIdxTpdoMap + n));
}
size_t RpdoLength(const ObjectDictionary& od, int n) {
  return MappingLength(od, static_cast<uint16_t>(kIdxRpdoMap + n));
}

Status PackTpdo(const ObjectDictionary& od, int n, hal::CanFrame* out) {
  const uint16_t map_index = static_cast<uint16_t>(kIdxTpdoMap + n);
  hal::CanFrame f;
  f.id = CanIdOf(TpdoCobId(od, n));
  const uint8_t count = static_cast<uint8_t>(od.Get(map_index, 0));
  size_t pos = 0;
  for (uint8_t k = 1; k <= count; ++k) {
    const MappedObject m = Mapped(od, map_index, k);
    const OdEntry* e = od.Find(m.index, m.sub);
    if (e == nullptr || e->string_slot >= 0 || pos + m.bytes > hal::kCanMaxDataBytes) {
      return Status::Error(StatusCode::kInternal, "TPDO%d maps 0x%04X sub %u, which cannot be sent",
                           n + 1, m.index, m.sub);
    }
    for (uint8_t b = 0; b < m.bytes; ++b) {
      f.data[pos++] = static_cast<uint8_t>(e->value >> (8 * b));
    }
  }
  f.len = static_cast<uint8_t>(pos);
  *out = f;
  return Status::Ok();
}

int RpdoFor(const ObjectDictionary& od, const hal::CanFrame& frame) {
  if (frame.extended || frame.rtr || frame.error) return -1;
  for (int n = 0; n < kRpdoCount; ++n) {
    const uint32_t cob = RpdoCobId(od, n);
    if (CobIdValid(cob) && CanIdOf(cob) == frame.id) return n;
  }
  return -1;
}

SdoAbort UnpackRpdo(ObjectDictionary* od, int n, const hal::CanFrame& frame) {
  const uint16_t map_index = static_cast<uint16_t>(kIdxRpdoMap + n);
  const uint8_t count = static_cast<uint8_t>(od->Get(map_index, 0));
  if (frame.len < MappingLength(*od, map_index)) return SdoAbort::kLengthTooLow;
  uint32_t values[8] = {};
  size_t pos = 0;
  for (uint8_t k = 1; k <= count && k <= 8; ++k) {
    const MappedObject m = Mapped(*od, map_index, k);
    const SdoAbort checked =
        od->CheckWrite(m.index, m.sub, &frame.data[pos], m.bytes, &values[k - 1]);
    if (checked != SdoAbort::kNone) return checked;
    pos += m.bytes;
  }
  for (uint8_t k = 1; k <= count && k <= 8; ++k) {
    const MappedObject m = Mapped(*od, map_index, k);
    (void)od->Set(m.index, m.sub, values[k - 1]);
  }
  return SdoAbort::kNone;
}

void ApplyResultMode(ObjectDictionary* od, ResultMode mode) {
  const bool stream = mode != ResultMode::kPdo;
  const bool answers = mode != ResultMode::kStream;
  const auto set_valid = [od](int n, bool valid) {
    const uint16_t index = static_cast<uint16_t>(kIdxTpdoComm + n);
    const uint32_t cob = od->Get(index, 1);
    (void)od->Set(index, 1, valid ? cob & ~kCobIdInvalid : cob | kCobIdInvalid);
  };
  set_valid(kTpdoStreamObject, stream);
  set_valid(kTpdoStreamEnd, stream);
  for (int k = 0; k < kTpdoAnswerCount; ++k) set_valid(kTpdoAnswerFirst + k, answers);
}

bool IsPdoCobIdEntry(const OdEntry& e) {
  return e.sub == 1 && ((e.index >= kIdxRpdoComm && e.index < kIdxRpdoComm + kRpdoCount) ||
                        (e.index >= kIdxTpdoComm && e.index < kIdxTpdoComm + kTpdoCount));
}

SdoAbort CheckCobIdWrite(const OdEntry& e, uint32_t value) {
  if (value & kCobIdExtended) return SdoAbort::kInvalidValue;  // 11-bit identifiers only
  const uint32_t id = CanIdOf(value);
  const uint32_t current = e.value;
  if (id == CanIdOf(current)) return SdoAbort::kNone;  // only the valid/RTR bits change
  const bool movable = e.index >= kIdxTpdoComm + kTpdoAnswerFirst &&
                       e.index < kIdxTpdoComm + kTpdoAnswerFirst + kTpdoAnswerCount;
  // CiA 301: the identifier of a valid PDO cannot change; switch it off first.
  if (!movable || CobIdValid(current) || (value & 0x1FFFF800u) != 0 || Restricted(id)) {
    return SdoAbort::kInvalidValue;
  }
  return SdoAbort::kNone;
}

}  // namespace sh::canopen
