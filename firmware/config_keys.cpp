#include "firmware/config_keys.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <type_traits>

#include "firmware/fw_config.hpp"
#include "recog/pipeline/worker_pool.hpp"
#include "tables/model_set.hpp"

namespace sh::fw {
namespace {

static_assert(kMaxConfigThreads == kMaxPoolThreads, "threads: the pipeline's limit");
static_assert(std::is_standard_layout_v<FwConfig>, "keys address FwConfig fields by offset");

// The table rows, from the key list: the field's place and size come from the FwConfig member.
#define SH_FIELD(name) offsetof(FwConfig, name), sizeof(FwConfig::name)
#define SH_INT(name, type, def, lo, hi, unit, help) \
  {#name, KeyType::kInt, SH_FIELD(name), std::is_signed_v<type>, lo, hi, nullptr, unit, help},
#define SH_INT_OR_OFF(name, type, def, lo, hi, unit, help) \
  {#name, KeyType::kIntOrOff, SH_FIELD(name), std::is_signed_v<type>, lo, hi, nullptr, unit, help},
#define SH_MASK(name, type, def, help) \
  {#name, KeyType::kMask, SH_FIELD(name), false, 1, 0xFFFFFFFFll, nullptr, "", help},
#define SH_CRC32(name, help) \
  {#name, KeyType::kCrc32, SH_FIELD(name), false, 0, 0xFFFFFFFFll, nullptr, "", help},
#define SH_BOOL(name, def, help) \
  {#name, KeyType::kBool, SH_FIELD(name), false, 0, 1, nullptr, "", help},
#define SH_CHOICE(name, type, def, choices, help) \
  {#name, KeyType::kChoice, SH_FIELD(name), false, 0, 0, choices, "", help},
#define SH_TEXT(name, capacity, def, help) \
  {#name, KeyType::kText, SH_FIELD(name), false, 0, 0, nullptr, "", help},
#define SH_VEC3(name, x, y, z, unit, help) \
  {#name, KeyType::kVec3, SH_FIELD(name), true, 0, 0, nullptr, unit, help},

const ConfigKey kKeys[] = {STEREOHASH_FW_CONFIG_KEYS(SH_INT, SH_INT_OR_OFF, SH_MASK, SH_CRC32,
                                                     SH_BOOL, SH_CHOICE, SH_TEXT, SH_VEC3)};
static_assert(sizeof(kKeys) / sizeof(kKeys[0]) == static_cast<size_t>(ConfigKeyId::kCount));

// Choice fields hold the index of the name: one byte, enumerators in the order of the names.
#define SH_CHOICE_TYPE(name, type, def, choices, help) \
  static_assert(sizeof(type) == 1, #name ": a choice is a one-byte enumeration");
#define SH_IGNORE(...)
STEREOHASH_FW_CONFIG_KEYS(SH_IGNORE, SH_IGNORE, SH_IGNORE, SH_IGNORE, SH_IGNORE, SH_CHOICE_TYPE,
                          SH_IGNORE, SH_IGNORE)
static_assert(
    static_cast<int>(Backend::kSim) == 1 && static_cast<int>(RecognitionKind::kTruth) == 1 &&
    static_cast<int>(SimCameraFault::kDropRight) == 2 &&
    static_cast<int>(CameraSource::kDirectory) == 2 &&
    static_cast<int>(OutputFrameKey::kRobot) == 2 && static_cast<int>(BackgroundKey::kLight) == 2 &&
    static_cast<int>(TableSurface::kLight) == 1 && static_cast<int>(VolumeFrame::kTable) == 1 &&
    static_cast<int>(RecordFormat::kPgm) == 1 && static_cast<int>(canopen::ResultMode::kBoth) == 2);

#undef SH_FIELD
#undef SH_INT
#undef SH_INT_OR_OFF
#undef SH_MASK
#undef SH_CRC32
#undef SH_BOOL
#undef SH_CHOICE
#undef SH_TEXT
#undef SH_VEC3
#undef SH_CHOICE_TYPE
#undef SH_IGNORE

uint8_t* FieldOf(const ConfigKey& key, FwConfig* c) {
  return reinterpret_cast<uint8_t*>(c) + key.offset;
}
const uint8_t* FieldOf(const ConfigKey& key, const FwConfig& c) {
  return reinterpret_cast<const uint8_t*>(&c) + key.offset;
}

void StoreInt(uint8_t* field, size_t size, long long v) {
  switch (size) {
    case 1: {
      const uint8_t x = static_cast<uint8_t>(v);
      std::memcpy(field, &x, 1);
      break;
    }
    case 2: {
      const uint16_t x = static_cast<uint16_t>(v);
      std::memcpy(field, &x, 2);
      break;
    }
    case 4: {
      const uint32_t x = static_cast<uint32_t>(v);
      std::memcpy(field, &x, 4);
      break;
    }
    default: {
      const uint64_t x = static_cast<uint64_t>(v);
      std::memcpy(field, &x, 8);
      break;
    }
  }
}

long long LoadInt(const uint8_t* field, size_t size, bool is_signed) {
  switch (size) {
    case 1: {
      uint8_t x;
      std::memcpy(&x, field, 1);
      return is_signed ? static_cast<int8_t>(x) : x;
    }
    case 2: {
      uint16_t x;
      std::memcpy(&x, field, 2);
      return is_signed ? static_cast<int16_t>(x) : x;
    }
    case 4: {
      uint32_t x;
      std::memcpy(&x, field, 4);
      return is_signed ? static_cast<int32_t>(x) : static_cast<long long>(x);
    }
    default: {
      int64_t x;
      std::memcpy(&x, field, 8);
      return x;
    }
  }
}

// The index of `value` among the '|'-separated names, or -1.
int ChoiceIndex(const char* choices, const char* value) {
  const size_t n = std::strlen(value);
  int index = 0;
  for (const char* p = choices;; ++index) {
    const char* end = std::strchr(p, '|');
    const size_t len = end ? size_t(end - p) : std::strlen(p);
    if (len == n && std::strncmp(p, value, n) == 0) return index;
    if (end == nullptr) return -1;
    p = end + 1;
  }
}

// Name number `index` of the choices into out.
void ChoiceName(const char* choices, int index, char* out, size_t capacity) {
  const char* p = choices;
  for (int i = 0; i < index && p != nullptr; ++i) {
    p = std::strchr(p, '|');
    if (p != nullptr) ++p;
  }
  if (p == nullptr) {
    std::snprintf(out, capacity, "?");
    return;
  }
  const char* end = std::strchr(p, '|');
  const int len = end ? int(end - p) : int(std::strlen(p));
  std::snprintf(out, capacity, "%.*s", len, p);
}

// "a, b or c" (separator ", ", last " or ").
void ChoiceList(const char* choices, const char* separator, const char* last_separator, char* out,
                size_t capacity) {
  size_t used = 0;
  out[0] = '\0';
  int count = 1;
  for (const char* p = choices; *p; ++p) count += *p == '|';
  for (int i = 0; i < count && used < capacity; ++i) {
    char name[64];
    ChoiceName(choices, i, name, sizeof(name));
    const char* sep = i == 0 ? "" : (i == count - 1 ? last_separator : separator);
    used += size_t(std::snprintf(out + used, capacity - used, "%s%s", sep, name));
  }
}

// Exactly the two words the documentation and the message name.
bool ParseBool(const char* text, bool* out) {
  if (!std::strcmp(text, "true") || !std::strcmp(text, "false")) {
    *out = text[0] == 't';
    return true;
  }
  return false;
}

// Three numbers separated by spaces or commas.
bool ParseVec3(const char* text, float out[3]) {
  const char* p = text;
  for (int i = 0; i < 3; ++i) {
    while (IsConfigBlank(*p) || *p == ',') ++p;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    if (errno != 0 || end == p || !(v > -1e6 && v < 1e6)) return false;
    out[i] = static_cast<float>(v);
    p = end;
  }
  while (IsConfigBlank(*p)) ++p;
  return *p == '\0';
}

void PrintCell(std::FILE* out, const char* text) {
  for (const char* p = text; *p; ++p) {
    if (*p == '|') {
      std::fputs("\\|", out);
    } else {
      std::fputc(*p, out);
    }
  }
}

}  // namespace

const ConfigKey* ConfigKeys() { return kKeys; }
size_t ConfigKeyCount() { return sizeof(kKeys) / sizeof(kKeys[0]); }

const ConfigKey* FindConfigKey(const char* name) {
  for (const ConfigKey& k : kKeys) {
    if (!std::strcmp(k.name, name)) return &k;
  }
  return nullptr;
}

void CopyConfigKey(const ConfigKey& key, const FwConfig& from, FwConfig* to) {
  std::memcpy(FieldOf(key, to), FieldOf(key, from), key.size);
  to->given.Add(static_cast<size_t>(&key - kKeys));
}

Status ApplyConfigKey(const ConfigKey& key, const char* value, FwConfig* config) {
  uint8_t* field = FieldOf(key, config);
  switch (key.type) {
    case KeyType::kInt:
    case KeyType::kIntOrOff:
    case KeyType::kMask: {
      char* end = nullptr;
      errno = 0;
      const long long v = std::strtoll(value, &end, 0);
      const bool off = key.type == KeyType::kIntOrOff && v == 0;
      if (errno != 0 || end == value || *end != '\0' || (!off && (v < key.min || v > key.max))) {
        if (key.type == KeyType::kMask) {
          return Status::Error(StatusCode::kInvalidArgument, "expected a non-zero 32-bit mask");
        }
        return Status::Error(StatusCode::kInvalidArgument, "expected %san integer in %lld..%lld",
                             key.type == KeyType::kIntOrOff ? "0 (off) or " : "", key.min, key.max);
      }
      StoreInt(field, key.size, v);
      break;
    }
    case KeyType::kCrc32: {
      uint32_t crc = 0;
      if (!ParseBlobCrc32(value, &crc)) {
        return Status::Error(StatusCode::kInvalidArgument,
                             "expected 0 (not checked) or a CRC-32 of up to 8 hex digits");
      }
      std::memcpy(field, &crc, sizeof(crc));
      break;
    }
    case KeyType::kBool: {
      bool b = false;
      if (!ParseBool(value, &b)) {
        return Status::Error(StatusCode::kInvalidArgument, "expected true or false");
      }
      std::memcpy(field, &b, sizeof(b));
      break;
    }
    case KeyType::kChoice: {
      const int index = ChoiceIndex(key.choices, value);
      if (index < 0) {
        char list[160];
        ChoiceList(key.choices, ", ", " or ", list, sizeof(list));
        return Status::Error(StatusCode::kInvalidArgument, "expected %s", list);
      }
      // The field is a one-byte enumeration: the index is its value.
      const uint8_t x = static_cast<uint8_t>(index);
      std::memcpy(field, &x, 1);
      break;
    }
    case KeyType::kText: {
      const size_t n = std::strlen(value);
      if (n + 1 > key.size) {
        return Status::Error(StatusCode::kInvalidArgument, "too long (at most %zu characters)",
                             key.size - 1);
      }
      std::memcpy(field, value, n + 1);
      break;
    }
    case KeyType::kVec3: {
      float v[3];
      if (!ParseVec3(value, v)) {
        return Status::Error(StatusCode::kInvalidArgument, "expected three numbers%s%s",
                             key.unit[0] ? " in " : "", key.unit);
      }
      std::memcpy(field, v, sizeof(v));
      break;
    }
  }
  config->given.Add(static_cast<size_t>(&key - kKeys));
  return Status::Ok();
}

void FormatConfigValue(const ConfigKey& key, const FwConfig& config, char* out, size_t capacity) {
  const uint8_t* field = FieldOf(key, config);
  switch (key.type) {
    case KeyType::kInt:
    case KeyType::kIntOrOff: {
      const long long v = LoadInt(field, key.size, key.is_signed);
      if (key.size == 8 && !key.is_signed) {
        std::snprintf(out, capacity, "%llu", static_cast<unsigned long long>(v));
      } else {
        std::snprintf(out, capacity, "%lld", v);
      }
      break;
    }
    case KeyType::kMask:
      std::snprintf(out, capacity, "0x%llX",
                    static_cast<unsigned long long>(LoadInt(field, key.size, false)));
      break;
    case KeyType::kCrc32: {
      uint32_t crc = 0;
      std::memcpy(&crc, field, sizeof(crc));
      std::snprintf(out, capacity, crc == 0 ? "0" : "%08x", crc);
      break;
    }
    case KeyType::kBool: {
      bool b = false;
      std::memcpy(&b, field, sizeof(b));
      std::snprintf(out, capacity, "%s", b ? "true" : "false");
      break;
    }
    case KeyType::kChoice:
      ChoiceName(key.choices, field[0], out, capacity);
      break;
    case KeyType::kText:
      std::snprintf(out, capacity, "%s", reinterpret_cast<const char*>(field));
      break;
    case KeyType::kVec3: {
      float v[3];
      std::memcpy(v, field, sizeof(v));
      std::snprintf(out, capacity, "%g %g %g", double(v[0]), double(v[1]), double(v[2]));
      break;
    }
  }
}

void FormatConfigType(const ConfigKey& key, char* out, size_t capacity) {
  const char* unit_sep = key.unit[0] != '\0' ? " " : "";
  switch (key.type) {
    case KeyType::kInt:
      std::snprintf(out, capacity, "integer %lld..%lld%s%s", key.min, key.max, unit_sep, key.unit);
      break;
    case KeyType::kIntOrOff:
      std::snprintf(out, capacity, "0 (off) or integer %lld..%lld%s%s", key.min, key.max, unit_sep,
                    key.unit);
      break;
    case KeyType::kMask:
      std::snprintf(out, capacity, "32-bit mask, not 0");
      break;
    case KeyType::kCrc32:
      std::snprintf(out, capacity, "0 (not checked) or CRC-32 (8 hex digits)");
      break;
    case KeyType::kBool:
      std::snprintf(out, capacity, "true | false");
      break;
    case KeyType::kChoice:
      ChoiceList(key.choices, " | ", " | ", out, capacity);
      break;
    case KeyType::kText:
      std::snprintf(out, capacity, "text, up to %zu characters", key.size - 1);
      break;
    case KeyType::kVec3:
      std::snprintf(out, capacity, "three numbers%s%s", unit_sep, key.unit);
      break;
  }
}

void PrintConfigKeys(std::FILE* out, const FwConfig& defaults) {
  std::fprintf(out, "configuration keys (`key = value` lines, # comments):\n");
  for (const ConfigKey& k : kKeys) {
    char type[192], value[kConfigPathMax];
    FormatConfigType(k, type, sizeof(type));
    FormatConfigValue(k, defaults, value, sizeof(value));
    std::fprintf(out, "  %-24s %s; default %s\n  %-24s %s\n", k.name, type,
                 value[0] ? value : "(empty)", "", k.help);
  }
}

void PrintConfigKeysMarkdown(std::FILE* out, const FwConfig& board_defaults,
                             const FwConfig& sim_defaults) {
  std::fprintf(out,
               "| Key | Accepts | Default (board) | Simulator | Meaning |\n"
               "|-----|---------|-----------------|-----------|---------|\n");
  for (const ConfigKey& k : kKeys) {
    char type[192], board[kConfigPathMax], sim[kConfigPathMax];
    FormatConfigType(k, type, sizeof(type));
    FormatConfigValue(k, board_defaults, board, sizeof(board));
    FormatConfigValue(k, sim_defaults, sim, sizeof(sim));
    std::fprintf(out, "| `%s` | ", k.name);
    PrintCell(out, type);
    std::fprintf(out, " | %s%s%s | ", board[0] ? "`" : "(empty)", board, board[0] ? "`" : "");
    if (std::strcmp(board, sim) != 0) {
      std::fprintf(out, "%s%s%s", sim[0] ? "`" : "(empty)", sim, sim[0] ? "`" : "");
    }
    std::fputs(" | ", out);
    PrintCell(out, k.help);
    std::fputs(" |\n", out);
  }
}

}  // namespace sh::fw
