// The runtime object dictionary built from kOdTable (od_table.hpp): one value per entry, in
// fixed storage (no heap), looked up by (index, sub-index).
//
// Two kinds of access:
//  - from the bus (Read/Write, used by the SDO server and the RPDO unpacker): access rights,
//    lengths and limits are checked and answered with the CiA 301 abort code; a WriteHandler may
//    veto or act on a write before it is stored;
//  - from the device (Set/Get): no checks, the device keeps read-only values current (error
//    register, results, identity).
// Not thread-safe: the firmware serialises access with its own lock.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/canopen/od_table.hpp"
#include "firmware/canopen/od_types.hpp"

namespace sh::canopen {

// VISIBLE_STRING capacity per entry (without the terminating NUL): model names are at most 31
// characters, version strings shorter.
inline constexpr size_t kOdStringCapacity = 40;

struct OdEntry {
  uint16_t index = 0;
  uint8_t sub = 0;
  uint8_t instance = 0;           // repetition of a repeated object (index - object's first index)
  const OdRow* row = nullptr;     // the entry's row (type, access, limits)
  const OdRow* object = nullptr;  // the row that opened the object (code, name)
  uint32_t value = 0;             // numeric value, two's complement in the type's width
  int16_t string_slot = -1;       // VISIBLE_STRING storage, -1 for numbers

  DataType type() const { return row->type; }
  Access access() const { return row->access; }
};

class WriteHandler {
 public:
  virtual ~WriteHandler() = default;
  // A bus write of a numeric entry passed the access, length and limit checks. Return kNone to
  // let the dictionary store `value` (raw, two's complement in the type's width), else the abort
  // code to answer. The handler may Set() other entries.
  virtual SdoAbort OnWrite(const OdEntry& entry, uint32_t value) = 0;
};

class ObjectDictionary {
 public:
  // All entries at their defaults for node id 1.
  ObjectDictionary();
  ObjectDictionary(const ObjectDictionary&) = delete;
  ObjectDictionary& operator=(const ObjectDictionary&) = delete;

  void set_write_handler(WriteHandler* handler) { handler_ = handler; }

  // CiA 301 reset communication: writable and node-id relative entries of the communication area
  // (0x1000..0x1FFF) return to their defaults, COB-IDs for `node_id`.
  void ResetCommunication(uint8_t node_id);
  uint8_t node_id() const { return node_id_; }

  size_t size() const { return count_; }
  const OdEntry& entry(size_t i) const { return entries_[i]; }
  // kNone with *out set, kNoObject (no such index) or kNoSubIndex.
  SdoAbort Lookup(uint16_t index, uint8_t sub, const OdEntry** out) const;
  const OdEntry* Find(uint16_t index, uint8_t sub) const;

  // Bus read: the value's bytes (little-endian; strings without NUL) into out[0..capacity).
  SdoAbort Read(uint16_t index, uint8_t sub, uint8_t* out, size_t capacity, size_t* length) const;
  // Bus write of `length` bytes (little-endian).
  SdoAbort Write(uint16_t index, uint8_t sub, const uint8_t* data, size_t length);
  // The checks of a bus write of a numeric entry (existence, access, length, limits) without
  // the handler and without storing; *raw receives the value.
  SdoAbort CheckWrite(uint16_t index, uint8_t sub, const uint8_t* data, size_t length,
                      uint32_t* raw) const;
  // Length in bytes of an entry's current value (strings: their length).
  size_t ValueLength(const OdEntry& entry) const;

  // Device side. Set stores the low bytes of `value` in the entry's width; false if there is no
  // such numeric entry.
  bool Set(uint16_t index, uint8_t sub, int64_t value);
  uint32_t Get(uint16_t index, uint8_t sub) const;                // raw; 0 if absent
  int64_t GetSigned(uint16_t index, uint8_t sub) const;           // sign-extended for signed types
  bool SetString(uint16_t index, uint8_t sub, const char* text);  // truncated to capacity
  const char* GetString(uint16_t index, uint8_t sub) const;       // "" if absent

  // Value of `raw` as a number of the entry's type (sign-extended for signed types).
  static int64_t Decode(DataType type, uint32_t raw);

 private:
  SdoAbort CheckLimits(const OdEntry& e, uint32_t raw) const;
  void SetDefault(OdEntry* e);

  OdEntry entries_[kMaxOdEntries];
  size_t count_ = 0;
  char strings_[kMaxOdStrings][kOdStringCapacity + 1] = {};
  size_t string_count_ = 0;
  uint8_t node_id_ = 1;
  WriteHandler* handler_ = nullptr;
};

}  // namespace sh::canopen
