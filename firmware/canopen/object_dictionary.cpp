#include "firmware/canopen/object_dictionary.hpp"

#include <cassert>
#include <cstring>

namespace sh::canopen {
namespace {

uint32_t WidthMask(DataType type) {
  const size_t bytes = DataTypeSize(type);
  return bytes >= 4 ? 0xFFFFFFFFu : (1u << (8 * bytes)) - 1;
}

bool Less(uint16_t index_a, uint8_t sub_a, uint16_t index_b, uint8_t sub_b) {
  return index_a != index_b ? index_a < index_b : sub_a < sub_b;
}

// The automatic sub-index 0 of a RECORD/ARRAY: const U8 holding the highest sub-index.
constexpr OdRow kAutoSub0 =
    Sub(0, 0, "Highest sub-index supported", DataType::kUnsigned8, Access::kConst, 0);

}  // namespace

int64_t ObjectDictionary::Decode(DataType type, uint32_t raw) {
  switch (type) {
    case DataType::kInteger8:
      return static_cast<int8_t>(raw & 0xFF);
    case DataType::kInteger16:
      return static_cast<int16_t>(raw & 0xFFFF);
    case DataType::kInteger32:
      return static_cast<int32_t>(raw);
    default:
      return static_cast<int64_t>(raw & WidthMask(type));
  }
}

ObjectDictionary::ObjectDictionary() {
  size_t r = 0;
  while (r < kOdRowCount) {
    const OdRow& obj = kOdTable[r];
    size_t end = r + 1;
    while (end < kOdRowCount && !kOdTable[end].opens_object) ++end;
    for (uint8_t instance = 0; instance < obj.repeat; ++instance) {
      const uint16_t index = static_cast<uint16_t>(obj.index + instance);
      if (obj.code == ObjectCode::kVar) {
        OdEntry& e = entries_[count_++];
        e.index = index;
        e.sub = 0;
        e.instance = instance;
        e.row = &obj;
        e.object = &obj;
        continue;
      }
      const bool declares_sub0 = end > r + 1 && kOdTable[r + 1].sub == 0;
      uint8_t highest = 0;
      for (size_t s = r + 1; s < end; ++s) {
        const uint8_t last = static_cast<uint8_t>(kOdTable[s].sub + kOdTable[s].sub_repeat - 1);
        if (last > highest) highest = last;
      }
      if (!declares_sub0) {
        OdEntry& e = entries_[count_++];
        e.index = index;
        e.sub = 0;
        e.instance = instance;
        e.row = &kAutoSub0;
        e.object = &obj;
        e.value = highest;
      }
      for (size_t s = r + 1; s < end; ++s) {
        for (uint8_t k = 0; k < kOdTable[s].sub_repeat; ++k) {
          OdEntry& e = entries_[count_++];
          e.index = index;
          e.sub = static_cast<uint8_t>(kOdTable[s].sub + k);
          e.instance = instance;
          e.row = &kOdTable[s];
          e.object = &obj;
        }
      }
    }
    r = end;
  }
  assert(count_ == kOdEntryCount);
  for (size_t i = 0; i < count_; ++i) {
    OdEntry& e = entries_[i];
    assert(i == 0 || Less(entries_[i - 1].index, entries_[i - 1].sub, e.index, e.sub));
    if (e.type() == DataType::kVisibleString) {
      assert(string_count_ < kMaxOdStrings);
      e.string_slot = static_cast<int16_t>(string_count_++);
    }
    if (e.row != &kAutoSub0) SetDefault(&e);
  }
}

void ObjectDictionary::SetDefault(OdEntry* e) {
  if (e->string_slot >= 0) {
    (void)SetString(e->index, e->sub, e->row->text != nullptr ? e->row->text : "");
    return;
  }
  const int64_t v = e->row->value + (e->row->node_id_relative ? node_id_ : 0);
  e->value = static_cast<uint32_t>(v) & WidthMask(e->type());
}

void ObjectDictionary::ResetCommunication(uint8_t node_id) {
  node_id_ = node_id;
  for (size_t i = 0; i < count_; ++i) {
    OdEntry& e = entries_[i];
    if (e.index < 0x1000 || e.index > 0x1FFF) continue;
    if (e.row->node_id_relative || Writable(e.access())) SetDefault(&e);
  }
}

const OdEntry* ObjectDictionary::Find(uint16_t index, uint8_t sub) const {
  size_t lo = 0, hi = count_;
  while (lo < hi) {
    const size_t mid = (lo + hi) / 2;
    if (Less(entries_[mid].index, entries_[mid].sub, index, sub)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  if (lo < count_ && entries_[lo].index == index && entries_[lo].sub == sub) return &entries_[lo];
  return nullptr;
}

SdoAbort ObjectDictionary::Lookup(uint16_t index, uint8_t sub, const OdEntry** out) const {
  const OdEntry* e = Find(index, sub);
  if (e != nullptr) {
    *out = e;
    return SdoAbort::kNone;
  }
  // Sub-index 0 exists for every object, so its absence means the object is absent.
  return Find(index, 0) != nullptr ? SdoAbort::kNoSubIndex : SdoAbort::kNoObject;
}

size_t ObjectDictionary::ValueLength(const OdEntry& e) const {
  if (e.string_slot >= 0) return std::strlen(strings_[e.string_slot]);
  return DataTypeSize(e.type());
}

SdoAbort ObjectDictionary::Read(uint16_t index, uint8_t sub, uint8_t* out, size_t capacity,
                                size_t* length) const {
  const OdEntry* e = nullptr;
  const SdoAbort found = Lookup(index, sub, &e);
  if (found != SdoAbort::kNone) return found;
  if (!Readable(e->access())) return SdoAbort::kWriteOnly;
  const size_t n = ValueLength(*e);
  if (n > capacity) return SdoAbort::kLengthTooHigh;
  if (e->string_slot >= 0) {
    std::memcpy(out, strings_[e->string_slot], n);
  } else {
    for (size_t i = 0; i < n; ++i) out[i] = static_cast<uint8_t>(e->value >> (8 * i));
  }
  *length = n;
  return SdoAbort::kNone;
}

SdoAbort ObjectDictionary::CheckLimits(const OdEntry& e, uint32_t raw) const {
  if (e.type() == DataType::kBoolean && raw > 1) return SdoAbort::kInvalidValue;
  if (!e.row->has_limits) return SdoAbort::kNone;
  const int64_t v = Decode(e.type(), raw);
  if (v < e.row->low) return SdoAbort::kValueTooLow;
  if (v > e.row->high) return SdoAbort::kValueTooHigh;
  return SdoAbort::kNone;
}

SdoAbort ObjectDictionary::CheckWrite(uint16_t index, uint8_t sub, const uint8_t* data,
                                      size_t length, uint32_t* raw) const {
  const OdEntry* e = nullptr;
  const SdoAbort looked_up = Lookup(index, sub, &e);
  if (looked_up != SdoAbort::kNone) return looked_up;
  if (!Writable(e->access()) && !e->row->same_value_writable) return SdoAbort::kReadOnly;
  if (e->string_slot >= 0) return SdoAbort::kLengthMismatch;  // not a number
  const size_t size = DataTypeSize(e->type());
  if (!Writable(e->access())) {
    // Only the value it holds, in its own width.
    uint32_t same = 0;
    for (size_t i = 0; i < size && i < length; ++i)
      same |= static_cast<uint32_t>(data[i]) << (8 * i);
    if (length != size || same != e->value) return SdoAbort::kReadOnly;
  }
  if (length > size) return SdoAbort::kLengthTooHigh;
  if (length < size) return SdoAbort::kLengthTooLow;
  uint32_t v = 0;
  for (size_t i = 0; i < size; ++i) v |= static_cast<uint32_t>(data[i]) << (8 * i);
  const SdoAbort limits = CheckLimits(*e, v);
  if (limits != SdoAbort::kNone) return limits;
  *raw = v;
  return SdoAbort::kNone;
}

SdoAbort ObjectDictionary::Write(uint16_t index, uint8_t sub, const uint8_t* data, size_t length) {
  const OdEntry* found = nullptr;
  const SdoAbort looked_up = Lookup(index, sub, &found);
  if (looked_up != SdoAbort::kNone) return looked_up;
  OdEntry& e = entries_[found - entries_];
  if (e.string_slot >= 0 && Writable(e.access())) {
    if (length > kOdStringCapacity) return SdoAbort::kLengthTooHigh;
    std::memcpy(strings_[e.string_slot], data, length);
    strings_[e.string_slot][length] = '\0';
    return SdoAbort::kNone;
  }
  uint32_t raw = 0;
  const SdoAbort checked = CheckWrite(index, sub, data, length, &raw);
  if (checked != SdoAbort::kNone) return checked;
  if (handler_ != nullptr) {
    const SdoAbort vetoed = handler_->OnWrite(e, raw);
    if (vetoed != SdoAbort::kNone) return vetoed;
  }
  e.value = raw;
  return SdoAbort::kNone;
}

bool ObjectDictionary::Set(uint16_t index, uint8_t sub, int64_t value) {
  const OdEntry* found = Find(index, sub);
  if (found == nullptr || found->string_slot >= 0) return false;
  OdEntry& e = entries_[found - entries_];
  e.value = static_cast<uint32_t>(value) & WidthMask(e.type());
  return true;
}

uint32_t ObjectDictionary::Get(uint16_t index, uint8_t sub) const {
  const OdEntry* e = Find(index, sub);
  return e != nullptr ? e->value : 0;
}

int64_t ObjectDictionary::GetSigned(uint16_t index, uint8_t sub) const {
  const OdEntry* e = Find(index, sub);
  return e != nullptr ? Decode(e->type(), e->value) : 0;
}

bool ObjectDictionary::SetString(uint16_t index, uint8_t sub, const char* text) {
  const OdEntry* e = Find(index, sub);
  if (e == nullptr || e->string_slot < 0) return false;
  std::strncpy(strings_[e->string_slot], text, kOdStringCapacity);
  strings_[e->string_slot][kOdStringCapacity] = '\0';
  return true;
}

const char* ObjectDictionary::GetString(uint16_t index, uint8_t sub) const {
  const OdEntry* e = Find(index, sub);
  return e != nullptr && e->string_slot >= 0 ? strings_[e->string_slot] : "";
}

}  // namespace sh::canopen
