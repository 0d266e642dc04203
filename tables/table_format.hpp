// The hash table blob: one hash function's hash arrays and the models they were built from,
// laid out to be used in place (memory-mapped, or linked into the binary as read-only data).
//
// Layout (all little-endian, every section starts at a multiple of kSectionAlignment bytes):
//
//   TableHeader                       fixed size, at offset 0
//   Model[n_models]                   model directory (recog/model/model.hpp)
//   BasisRecord[n_bases]              one per stored model basis (frame)
//   uint32 point_bin_offsets[n_point_bins + 1]
//   PointEntry[n_point_entries]       grouped by bin: bin i holds [offsets[i], offsets[i+1])
//   uint32 line_bin_offsets[n_line_bins + 1]
//   LineEntry[n_line_entries]         grouped by the bin of the line's support vector
//
// The CRC-32 covers every byte of the blob, its own field read as zero (BlobCrc32). See
// docs/tables.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "recog/base/fixed_point.hpp"
#include "recog/model/model.hpp"
#include "tables/blob_checks.hpp"

namespace sh {

inline constexpr char kTableMagic[8] = {'S', 'H', 'T', 'A', 'B', 'L', 'E', '\0'};
// Version 4: model edges record whether they are smooth (ModelEdge::smooth, 5 bytes an edge).
// Version 3: the CRC-32 covers the header too (version 2 left the header, with the hash function,
// grids and limits, outside it). Version 2: Model records sized for 128 corners, 192 edges,
// 64 faces of up to 64 corners and 96 symmetries (version 1: 32, 48, 24, 15, 24).
inline constexpr uint16_t kTableFormatVersion = 4;

// Capacities the recogniser's scratch memory is sized for; the loader refuses larger tables.
inline constexpr uint32_t kMaxTableModels = 16;
inline constexpr uint32_t kMaxTableBases = 8192;
inline constexpr uint32_t kMaxTablePointEntries = 65536;
inline constexpr uint32_t kMaxTableLineEntries = 65536;
inline constexpr uint32_t kMaxTableBins = 262144;

// The five 3-D hash functions (thesis table 5.1; the frames are in recog/hashing/basis.hpp). A
// table holds the hash arrays of one of them.
enum class HashFunction : uint8_t {
  kThreePointsFirst = 1,
  kThreePointsCentroid = 2,
  kTwoLines = 3,
  kLinePointFoot = 4,
  kLinePointMidway = 5,
};

inline bool IsValidHashFunction(int hf) { return hf >= 1 && hf <= 5; }
inline bool UsesThreePoints(HashFunction hf) {
  return hf == HashFunction::kThreePointsFirst || hf == HashFunction::kThreePointsCentroid;
}
inline bool UsesLinePoint(HashFunction hf) {
  return hf == HashFunction::kLinePointFoot || hf == HashFunction::kLinePointMidway;
}

// Geometric limits on bases, stored in the table header: scene bases outside them are not tried,
// model bases outside them are not stored.
struct BasisLimits {
  float min_point_line_mm = 20.0f;  // line+point: point-line distance window (thesis 4.3)
  float max_point_line_mm = 70.0f;
  float min_line_angle_deg = 37.0f;     // two lines: smallest angle between them
  float max_line_distance_mm = 70.0f;   // two lines: longest common perpendicular
  float min_point_spacing_mm = 5.0f;    // three points: shortest side
  float max_point_spacing_mm = 80.0f;   // three points: longest side (about the largest model)
  float min_triangle_height_mm = 3.0f;  // three points: distance of p2 from line p0-p1
};

// A uniform grid of cubic bins over a box.
struct GridGeometry {
  float min_mm[3];  // corner of bin (0, 0, 0)
  float bin_mm;     // edge length of a bin
  uint16_t dims[3];
  uint16_t reserved;
  uint32_t bin_count() const { return uint32_t{dims[0]} * dims[1] * dims[2]; }
};
static_assert(sizeof(GridGeometry) == 24);

struct TableHeader {
  char magic[8];
  uint16_t format_version;
  uint8_t hash_function;  // 1..5 (HashFunction)
  uint8_t reserved0;
  uint32_t header_size;  // sizeof(TableHeader)
  uint64_t total_size;   // whole blob in bytes
  uint32_t blob_crc32;   // CRC-32 of bytes [0, total_size) with this field read as zero
  uint32_t n_models;
  uint32_t n_bases;
  uint32_t n_point_entries;
  uint32_t n_line_entries;
  uint32_t max_point_bin_entries;  // largest bin, for information and scratch sizing
  uint32_t max_line_bin_entries;
  uint32_t reserved1;
  GridGeometry point_grid;
  GridGeometry line_grid;
  // Limits the model bases were built with; scene bases use the same.
  float min_point_line_mm, max_point_line_mm;
  float min_line_angle_deg, max_line_distance_mm;
  float min_point_spacing_mm, max_point_spacing_mm, min_triangle_height_mm;
  float reserved2;
  SectionRef models, bases, point_bins, point_entries, line_bins, line_entries;
  uint8_t reserved3[24];  // zero; pads the header to 256 bytes
};
static_assert(sizeof(TableHeader) == 256, "header layout is part of the format");
static_assert(offsetof(TableHeader, blob_crc32) == kBlobCrc32Offset);
static_assert(std::is_standard_layout_v<TableHeader>);

// The blob's CRC-32: every byte of [0, size), the header included, with blob_crc32 read as zero,
// so that no bit of the header (hash function, grids, limits, section offsets) can change
// unnoticed. `blob` holds at least sizeof(TableHeader) bytes.
uint32_t TableBlobCrc32(const uint8_t* blob, size_t size);

// One stored model basis (frame).
struct BasisRecord {
  uint16_t model;            // index into the model directory
  uint8_t features[3];       // corner/edge indices defining the basis (by hash function)
  uint8_t signs;             // bit 0: first line reversed, bit 1: second line reversed
  uint16_t n_point_entries;  // entries this basis stored, for vote normalisation
  uint16_t n_line_entries;
  uint16_t reserved;
  float basis_T_model[12];  // row-major R (9) then t_mm (3)
};
static_assert(sizeof(BasisRecord) == 60);

// A model point in a basis frame. Coordinates Q10.6 millimetres (raw = round(mm * 64)).
struct PointEntry {
  QCoordMm::Raw x, y, z;
  uint16_t basis;
};
static_assert(sizeof(PointEntry) == 8);

// A model edge in a basis frame: segment centre (Q10.6 mm), unit direction (Q2.14) and length
// (Q10.6 mm, unsigned range used). Binned by the support vector of its infinite line.
struct LineEntry {
  QCoordMm::Raw cx, cy, cz;
  QUnit::Raw vx, vy, vz;
  uint16_t length;  // Q10.6 mm as unsigned: raw = round(mm * 64), up to 1023 mm
  uint16_t basis;
};
static_assert(sizeof(LineEntry) == 16);

}  // namespace sh
