#include "recog/pipeline/table_carry.hpp"

#include <algorithm>
#include <cmath>

#include "recog/base/angles.hpp"

namespace sh {
namespace {

// Weight of the carried plane against one agreeing estimate: the mean of the first few, then a
// slow follow of a drifting mount.
constexpr uint32_t kMaxMergeWeight = 10;

}  // namespace

Status CheckTableCarryConfig(const TableCarryConfig& c) {
  if (c.confirm_frames < 1 || c.misfit_frames < 1 ||
      !(c.tolerance_mm > 0 && std::isfinite(c.tolerance_mm)) ||
      !(c.tolerance_deg > 0 && c.tolerance_deg < 90) ||
      !(c.min_resting_share >= 0 && c.min_resting_share <= 1)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "table carry: confirm_frames %u and misfit_frames %u must be at least 1, "
                         "tolerance_mm %g finite and positive, tolerance_deg %g in (0, 90), "
                         "min_resting_share %g in [0, 1]",
                         c.confirm_frames, c.misfit_frames, c.tolerance_mm, c.tolerance_deg,
                         c.min_resting_share);
  }
  return Status::Ok();
}

const char* TableCarryStateName(TableCarryState s) {
  switch (s) {
    case TableCarryState::kSearching:
      return "searching";
    case TableCarryState::kConfirming:
      return "confirming";
    case TableCarryState::kCarried:
      return "carried";
  }
  return "unknown";
}

bool PlanesAgree(const RigidTransform& a, const RigidTransform& b, float tolerance_mm,
                 float tolerance_deg) {
  const Eigen::Vector3f na = a.R.col(2), nb = b.R.col(2);
  const float angle_deg = std::acos(std::clamp(na.dot(nb), -1.0f, 1.0f)) * kRadToDeg;
  // Each origin's height over the other plane: a shift along the normal, and a tilt seen where
  // the objects are.
  const float a_over_b = nb.dot(a.t_mm - b.t_mm);
  const float b_over_a = na.dot(b.t_mm - a.t_mm);
  return angle_deg <= tolerance_deg && std::fabs(a_over_b) <= tolerance_mm &&
         std::fabs(b_over_a) <= tolerance_mm;
}

TableCarryUse TableCarry::Next(const TableCarryConfig& config) const {
  if (state_ != TableCarryState::kCarried || misfits_ > 0) return TableCarryUse::kEstimate;
  if (config.check_every_frames > 0 && carried_ >= config.check_every_frames) {
    return TableCarryUse::kEstimate;
  }
  return TableCarryUse::kCarry;
}

void TableCarry::Candidate(const RigidTransform& plane) {
  state_ = TableCarryState::kConfirming;
  left_T_table_ = plane;
  agreeing_ = 1;
  misfits_ = 0;
  carried_ = 0;
}

void TableCarry::Merge(const RigidTransform& plane) {
  const float w = static_cast<float>(std::min(agreeing_, kMaxMergeWeight));
  const Eigen::Vector3f up =
      (w * left_T_table_.R.col(2) + plane.R.col(2)).normalized();  // agreeing: never opposite
  const Eigen::Vector3f centre = (w * left_T_table_.t_mm + plane.t_mm) / (w + 1.0f);
  // The old x axis made perpendicular to the new normal (the frame's x, y are arbitrary in the
  // plane; keeping them stable keeps the reported frame still).
  const Eigen::Vector3f x_old = left_T_table_.R.col(0);
  const Eigen::Vector3f x = (x_old - x_old.dot(up) * up).normalized();
  left_T_table_.R.col(0) = x;
  left_T_table_.R.col(1) = up.cross(x);
  left_T_table_.R.col(2) = up;
  left_T_table_.t_mm = centre;
}

void TableCarry::ObserveEstimate(const TableCarryConfig& config, const TableEstimate& estimate) {
  if (!estimate.accepted()) return;  // no evidence either way
  const RigidTransform& plane = estimate.left_T_table;
  if (state_ == TableCarryState::kSearching) {
    Candidate(plane);
  } else if (PlanesAgree(left_T_table_, plane, config.tolerance_mm, config.tolerance_deg)) {
    Merge(plane);
    agreeing_ = std::min(agreeing_ + 1, 0xFFFFFFFEu);
    misfits_ = 0;
    carried_ = 0;
  } else if (state_ == TableCarryState::kConfirming) {
    Candidate(plane);  // disagrees: the count starts again from this one
    return;
  } else {
    carried_ = 0;
    if (++misfits_ >= config.misfit_frames) {
      ++drops_;
      Candidate(plane);
    }
    return;
  }
  if (state_ == TableCarryState::kConfirming && agreeing_ >= config.confirm_frames) {
    state_ = TableCarryState::kCarried;
  }
}

void TableCarry::ObserveCarried(const TableCarryConfig& config, uint32_t objects, uint32_t resting,
                                uint32_t sunk) {
  if (state_ != TableCarryState::kCarried) return;
  ++carried_;
  const bool few_resting =
      objects >= 2 &&
      static_cast<float>(resting) < config.min_resting_share * static_cast<float>(objects);
  const bool sinking = resting == 0 && sunk > config.max_sunk;
  if (!few_resting && !sinking) {
    misfits_ = 0;
    return;
  }
  if (++misfits_ >= config.misfit_frames) {
    ++drops_;
    state_ = TableCarryState::kSearching;
    agreeing_ = misfits_ = carried_ = 0;
  }
}

}  // namespace sh
