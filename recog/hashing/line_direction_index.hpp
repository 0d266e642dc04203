// The line entries of a hash table regrouped by direction, decoded to float once at Init.
//
// A scene line's look-up visits every line entry binned near its support vector, and the angle
// term of eq. 4.4 alone rules out about three in four of them: a long model edge votes only if
// it is nearly parallel to the scene line. Here the entries are sorted into direction classes
// (a cube map over the half sphere, classes 0 .. kClasses - 1); each class knows the axis its
// directions cluster about, their spread and its shortest edge, so one test per class and scene
// line skips the classes whose every entry would fail the angle test. The test is conservative
// (a margin of kClassSlackRad), so the entries left out are exactly ones that could not vote.
//
// Within a class, the entries keep the table's bin order, and offsets per class and bin give one
// contiguous range for a row of bins, as in the table itself. Each bin knows which classes it
// holds, so a row of bins is visited only for the classes that have entries there. Tables with more
// bins or entries than the capacities below are not indexed (built() is false) and are searched as
// they are.
//
// The decoded entries are kept as columns (one array per field), so that a look-up tests four
// consecutive entries at once (line_look_up.hpp); each column is padded by four so that the last
// group of a range may be read whole.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "recog/base/float4.hpp"
#include "tables/table_view.hpp"

namespace sh {

class LineDirectionIndex {
 public:
  static constexpr int kGridPerFace = 3;  // cube-map cells per face side
  static constexpr int kClasses = 3 * kGridPerFace * kGridPerFace;
  static constexpr uint32_t kMaxBins = 4096;      // line grid bins indexed at most
  static constexpr uint32_t kMaxEntries = 16384;  // line entries indexed at most
  static constexpr double kClassSlackRad = 0.02;  // margin of the class test
  static_assert(kClasses <= 64, "classes are a 64-bit mask");
  static_assert(kMaxEntries <= 65535, "offsets are 16-bit");

  // Decoded line entry: unit direction (Q2.14 decoded), length and segment centre in mm, and
  // the entry's index in the table.
  struct Entry {
    float ux, uy, uz, length_mm;
    float cx, cy, cz;
    uint32_t table_index;
  };

  // Indexes the line entries of `table` for an angle test that keeps an entry only while
  // length^2 (1 - cos^2 angle) < angle_cut_mm2. Returns false, and leaves the index unused,
  // when the table exceeds the capacities.
  bool Build(const TableView& table, float angle_cut_mm2);
  bool built() const { return built_; }
  void Clear() { built_ = false; }

  // Bit c set: class c may hold entries that pass the angle test against the unit scene
  // direction v (in the basis frame).
  uint64_t LiveClasses(const Eigen::Vector3f& v) const;

  // Classes with entries in bins [bin_lo, bin_hi] (bit c: class c); a class outside the mask
  // has an empty range there.
  uint64_t ClassesIn(uint32_t bin_lo, uint32_t bin_hi) const {
    uint64_t classes = 0;
    for (uint32_t b = bin_lo; b <= bin_hi; ++b) classes |= bin_classes_[b];
    return classes;
  }

  // Entries of class c in bins [bin_lo, bin_hi] (bins of the table's line grid).
  uint32_t begin(int c, uint32_t bin_lo) const { return offsets_[c][bin_lo]; }
  uint32_t end(int c, uint32_t bin_hi) const { return offsets_[c][bin_hi + 1]; }
  Entry entry(uint32_t i) const {
    return {ux_[i], uy_[i], uz_[i], length_mm_[i], cx_[i], cy_[i], cz_[i], table_index_[i]};
  }

  // Entries i .. i + 3 as four-lane columns (entries past the last read as zero-length at the
  // origin; a range's caller masks the lanes past its end).
  struct Lanes {
    Float4 ux, uy, uz, length_mm, cx, cy, cz;
  };
  Lanes LanesAt(uint32_t i) const {
    return {LoadFloat4(ux_ + i),        LoadFloat4(uy_ + i), LoadFloat4(uz_ + i),
            LoadFloat4(length_mm_ + i), LoadFloat4(cx_ + i), LoadFloat4(cy_ + i),
            LoadFloat4(cz_ + i)};
  }

  // The class of a direction (either sign).
  static int ClassOf(const Eigen::Vector3f& u);

 private:
  bool built_ = false;
  uint64_t non_empty_ = 0;                    // classes with entries
  float axis_[3][kClasses] = {};              // unit axis of each class, by component
  float min_abs_cos_[kClasses] = {};          // live while |v . axis| >= this
  uint16_t offsets_[kClasses][kMaxBins + 1];  // per class: bin -> first entry
  uint64_t bin_classes_[kMaxBins] = {};       // per bin: the classes with entries in it
  static constexpr uint32_t kPadded = kMaxEntries + kFloat4Lanes;
  float ux_[kPadded] = {}, uy_[kPadded] = {}, uz_[kPadded] = {}, length_mm_[kPadded] = {};
  float cx_[kPadded] = {}, cy_[kPadded] = {}, cz_[kPadded] = {};
  uint32_t table_index_[kMaxEntries] = {};

  void Store(uint32_t i, const Entry& e);
};

// A table line entry decoded to float (the values the vote computes with): Q10.6 mm and Q2.14
// unit components (table_format.hpp).
inline LineDirectionIndex::Entry DecodeLineEntry(const LineEntry& l, uint32_t table_index) {
  constexpr float kMmPerRaw = 1.0f / 64.0f;
  constexpr float kUnitPerRaw = 1.0f / 16384.0f;
  return {float(l.vx) * kUnitPerRaw, float(l.vy) * kUnitPerRaw,
          float(l.vz) * kUnitPerRaw, float(l.length) * kMmPerRaw,
          float(l.cx) * kMmPerRaw,   float(l.cy) * kMmPerRaw,
          float(l.cz) * kMmPerRaw,   table_index};
}

}  // namespace sh
