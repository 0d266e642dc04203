// Configuration of stereohash-fw and stereohash-fw-sim: a plain `key = value` text file. The keys
// are declared once, in config_keys.hpp (docs/firmware.md's table is printed from them). Parsing
// never throws and never allocates: strings live in fixed arrays, and the first problem is
// reported with its line number and key.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/config_keys.hpp"
#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"

namespace sh::fw {

inline constexpr size_t kMaxConfigFileBytes = size_t{64} * 1024;

// The configuration: one field per key (named as the key, with its default: the board's), and
// which keys a file gave.
struct FwConfig {
#define STEREOHASH_FW_FIELD(name, type, def, ...) type name = def;
#define STEREOHASH_FW_MASK_FIELD(name, type, def, help) type name = def;
#define STEREOHASH_FW_CRC32_FIELD(name, help) uint32_t name = 0;
#define STEREOHASH_FW_BOOL_FIELD(name, def, help) bool name = def;
#define STEREOHASH_FW_TEXT_FIELD(name, capacity, def, help) char name[capacity] = def;
#define STEREOHASH_FW_VEC3_FIELD(name, x, y, z, unit, help) float name[3] = {x, y, z};
  STEREOHASH_FW_CONFIG_KEYS(STEREOHASH_FW_FIELD, STEREOHASH_FW_FIELD, STEREOHASH_FW_MASK_FIELD,
                            STEREOHASH_FW_CRC32_FIELD, STEREOHASH_FW_BOOL_FIELD,
                            STEREOHASH_FW_FIELD, STEREOHASH_FW_TEXT_FIELD, STEREOHASH_FW_VEC3_FIELD)
#undef STEREOHASH_FW_FIELD
#undef STEREOHASH_FW_MASK_FIELD
#undef STEREOHASH_FW_CRC32_FIELD
#undef STEREOHASH_FW_BOOL_FIELD
#undef STEREOHASH_FW_TEXT_FIELD
#undef STEREOHASH_FW_VEC3_FIELD

  // The keys (ConfigKeyId) a file gave.
  ConfigKeySet given;
  // The simulator's default box over its rendered table (SimDefaults), until a file gives one.
  bool sim_volume_box = false;

  bool Given(ConfigKeyId key) const { return given.Has(static_cast<size_t>(key)); }
  // A working volume box: given, or the simulator's default.
  bool volume_set() const {
    return sim_volume_box || Given(ConfigKeyId::volume_min_mm) || Given(ConfigKeyId::volume_max_mm);
  }
  // The box is the simulator's default one (it belongs to the rendered table).
  bool volume_is_sim_default() const {
    return sim_volume_box && !Given(ConfigKeyId::volume_min_mm) &&
           !Given(ConfigKeyId::volume_max_mm);
  }
  // table_rotation_deg / table_origin_mm were given.
  bool table_pose_set() const {
    return Given(ConfigKeyId::table_rotation_deg) || Given(ConfigKeyId::table_origin_mm);
  }
};

// Parses `text` (need not be NUL-terminated) on top of the values already in *config. Lines:
// `key = value`, `#` starts a comment, blank lines are skipped. Unknown keys, repeated keys,
// malformed values and out-of-range numbers fail with "line N: key 'k': ...".
Status ParseConfig(const char* text, size_t length, FwConfig* config);

// Reads and parses a file (at most kMaxConfigFileBytes) on top of *config, then validates.
Status LoadConfigFile(const char* path, FwConfig* config);

// The table (conveyor) frame in the left camera from table_rotation_deg / table_origin_mm:
// x_left = R(rotation vector) x_table + origin.
RigidTransform TablePose(const FwConfig& c);

// Checks combinations (the board needs a calibration file and its own cameras, ...).
Status ValidateConfig(const FwConfig& config);

// Copies the keys of a list macro (`X(key) X(key) ...`) into the fields of the same names of a
// component's settings, each converted to its field's type: the key's range, checked when the
// file was read, fits it. A name that is no key, or no field of the component, does not
// compile, so a list cannot drift from the key table.
#define STEREOHASH_FW_COPY_KEY(name) \
  sh_out_->name = static_cast<decltype(sh_out_->name)>(sh_config_.name);
#define STEREOHASH_FW_COPY_KEYS(LIST, config_value, out_pointer) \
  do {                                                           \
    const FwConfig& sh_config_ = (config_value);                 \
    auto* sh_out_ = (out_pointer);                               \
    LIST(STEREOHASH_FW_COPY_KEY)                                 \
  } while (false)

}  // namespace sh::fw
