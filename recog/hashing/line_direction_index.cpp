#include "recog/hashing/line_direction_index.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sh {
namespace {

constexpr double kHalfPi = 1.5707963267948966;

// The axis with the largest magnitude component (the lowest on a tie).
int DominantAxis(const Eigen::Vector3f& u) {
  const Eigen::Vector3f a = u.cwiseAbs();
  return a.x() >= a.y() ? (a.x() >= a.z() ? 0 : 2) : (a.y() >= a.z() ? 1 : 2);
}

// u turned to the half sphere of its class (dominant component positive), in double.
Eigen::Vector3d Aligned(const Eigen::Vector3f& u) {
  const Eigen::Vector3d d = u.cast<double>();
  return d[DominantAxis(u)] < 0.0 ? Eigen::Vector3d(-d) : d;
}

}  // namespace

int LineDirectionIndex::ClassOf(const Eigen::Vector3f& u) {
  const int a = DominantAxis(u);
  const float dominant = std::fabs(u[a]);
  if (!(dominant > 0.0f)) return 0;
  const float sign = u[a] < 0.0f ? -1.0f : 1.0f;
  auto cell = [&](float component) {
    const float t = (sign * component / dominant + 1.0f) * 0.5f * float(kGridPerFace);
    return std::clamp(int(t), 0, kGridPerFace - 1);
  };
  return (a * kGridPerFace + cell(u[(a + 1) % 3])) * kGridPerFace + cell(u[(a + 2) % 3]);
}

bool LineDirectionIndex::Build(const TableView& table, float angle_cut_mm2) {
  built_ = false;
  const uint32_t bins = table.line_grid().bin_count(), n = table.line_entry_count();
  if (bins > kMaxBins || n > kMaxEntries) return false;
  const LineEntry* lines = table.line_entries();
  const uint32_t* bin_offsets = table.line_bin_offsets();

  // Count per class and bin, then place each class's entries in bin order.
  std::memset(offsets_, 0, sizeof(offsets_));
  std::memset(bin_classes_, 0, sizeof(bin_classes_));
  for (uint32_t b = 0; b < bins; ++b) {
    for (uint32_t e = bin_offsets[b]; e < bin_offsets[b + 1]; ++e) {
      const Entry d = DecodeLineEntry(lines[e], e);
      const int c = ClassOf({d.ux, d.uy, d.uz});
      ++offsets_[c][b + 1];
      bin_classes_[b] |= uint64_t{1} << c;
    }
  }
  uint32_t start = 0;
  for (int c = 0; c < kClasses; ++c) {
    offsets_[c][0] = uint16_t(start);
    for (uint32_t b = 1; b <= bins; ++b)
      offsets_[c][b] = uint16_t(offsets_[c][b] + offsets_[c][b - 1]);
    start = offsets_[c][bins];
  }
  uint32_t fill[kClasses];
  for (int c = 0; c < kClasses; ++c) fill[c] = offsets_[c][0];
  for (uint32_t b = 0; b < bins; ++b) {
    for (uint32_t e = bin_offsets[b]; e < bin_offsets[b + 1]; ++e) {
      const Entry d = DecodeLineEntry(lines[e], e);
      Store(fill[ClassOf({d.ux, d.uy, d.uz})]++, d);
    }
  }

  // Each class: the mean direction as its axis, the largest angle of a member to it, and the
  // shortest member, which passes the angle test furthest from the scene direction.
  non_empty_ = 0;
  for (int c = 0; c < kClasses; ++c) {
    const uint32_t begin = offsets_[c][0], end = offsets_[c][bins];
    min_abs_cos_[c] = 2.0f;  // empty: never live
    if (begin == end) continue;
    non_empty_ |= uint64_t{1} << c;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double min_length = 1e30;
    for (uint32_t i = begin; i < end; ++i) {
      sum += Aligned({ux_[i], uy_[i], uz_[i]}).normalized();
      min_length = std::min(min_length, double(length_mm_[i]));
    }
    const Eigen::Vector3d axis = sum.normalized();
    double spread = 0.0;
    for (uint32_t i = begin; i < end; ++i) {
      const Eigen::Vector3d u = Aligned({ux_[i], uy_[i], uz_[i]}).normalized();
      spread = std::max(spread, std::acos(std::clamp(std::fabs(u.dot(axis)), 0.0, 1.0)));
    }
    const double cut = double(angle_cut_mm2);
    const double reach =
        min_length * min_length <= cut ? kHalfPi : std::asin(std::sqrt(cut) / min_length);
    const double limit = spread + reach + kClassSlackRad;
    for (int k = 0; k < 3; ++k) axis_[k][c] = float(axis[k]);
    min_abs_cos_[c] = limit >= kHalfPi ? -1.0f : float(std::cos(limit));
  }
  built_ = true;
  return true;
}

void LineDirectionIndex::Store(uint32_t i, const Entry& e) {
  ux_[i] = e.ux;
  uy_[i] = e.uy;
  uz_[i] = e.uz;
  length_mm_[i] = e.length_mm;
  cx_[i] = e.cx;
  cy_[i] = e.cy;
  cz_[i] = e.cz;
  table_index_[i] = e.table_index;
}

uint64_t LineDirectionIndex::LiveClasses(const Eigen::Vector3f& v) const {
  // Every class at once, in a loop the compiler vectorises (an empty class never passes: its
  // min_abs_cos_ is 2), then the flags gathered into the mask.
  int32_t passes[kClasses];
  for (int c = 0; c < kClasses; ++c) {
    const float cos_axis = v.x() * axis_[0][c] + v.y() * axis_[1][c] + v.z() * axis_[2][c];
    passes[c] = std::fabs(cos_axis) >= min_abs_cos_[c] ? 1 : 0;
  }
  uint64_t live = 0;
  for (int c = 0; c < kClasses; ++c) live |= uint64_t(passes[c]) << c;
  return live & non_empty_;
}

}  // namespace sh
