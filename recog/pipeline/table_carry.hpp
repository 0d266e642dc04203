// The table plane carried between the frames of a fixed cell (cameras bolted over a conveyor):
// the table does not move, so once the per-frame estimate (table_estimate.hpp) has found the
// same plane in confirm_frames frames in a row, every later frame takes it as a given table
// (one search, the table check on, the features under it and far over it dropped) instead of
// searching twice. It is checked as it is used:
//  - a carried frame misfits when the objects found do not rest on the plane (fewer than
//    min_resting_share of them, with at least two found) or when more than max_sunk
//    hypotheses sank into it while none of the objects found rests on it;
//  - after a misfit, and every check_every_frames carried frames, the frame estimates the plane
//    again instead of carrying it; an estimate that agrees clears the misfits, one that
//    disagrees counts as a misfit, and misfit_frames misfits in a row drop the plane: the
//    disagreeing estimate (if any) becomes the new candidate, confirmed as the first was.
// Frames without evidence (an estimate refused, no objects) change nothing.
//
// Pure state over a few numbers: no I/O, no heap, copied freely (the firmware keeps it across a
// re-initialisation that does not move the cameras).
#pragma once

#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/pipeline/table_estimate.hpp"

namespace sh {

struct TableCarryConfig {
  // Carry the estimated plane between frames (PipelineConfig::table_estimate must be enabled
  // and no table given).
  bool enabled = false;
  // Accepted estimates in a row that must agree before the plane is carried.
  uint32_t confirm_frames = 3;
  // Agreement of two planes: the angle between their normals and the height of each one's
  // origin over the other. Estimates of one table agree to a few tenths of a millimetre and
  // degree (docs/pipeline.md, stage 4b); a table moved or tilted by hand exceeds both.
  float tolerance_mm = 2.0f;
  float tolerance_deg = 1.0f;
  // Misfits in a row that drop the carried plane.
  uint32_t misfit_frames = 2;
  // A carried frame with at least two objects misfits when fewer than this share rest on it.
  float min_resting_share = 0.5f;
  // ... or when more hypotheses than this sank into it and none of the objects found rests on
  // it (a plane above the real table rejects the true objects as sunk).
  uint32_t max_sunk = 8;
  // Carried frames between two checks by a fresh estimate (0: only after a misfit).
  uint32_t check_every_frames = 50;
};
Status CheckTableCarryConfig(const TableCarryConfig& config);

enum class TableCarryState : uint8_t {
  kSearching = 0,  // no candidate plane yet (or dropped): every frame estimates
  kConfirming,     // a candidate that agreed in `agreeing` frames in a row
  kCarried,        // confirmed: frames take it as their table
};
const char* TableCarryStateName(TableCarryState s);

// What a frame should do with the table.
enum class TableCarryUse : uint8_t {
  kEstimate = 0,  // estimate the plane from the frame (and report it to ObserveEstimate)
  kCarry,         // take left_T_table() as the frame's table (and report to ObserveCarried)
};

// Whether two planes (table frames, z up, top at z = 0) are the same within tolerance.
bool PlanesAgree(const RigidTransform& a, const RigidTransform& b, float tolerance_mm,
                 float tolerance_deg);

class TableCarry {
 public:
  void Reset() { *this = TableCarry(); }

  TableCarryUse Next(const TableCarryConfig& config) const;
  // An estimate made on this frame (Next() said kEstimate, or the caller estimated anyway).
  void ObserveEstimate(const TableCarryConfig& config, const TableEstimate& estimate);
  // A frame that carried the plane: objects found, how many rest on the plane, hypotheses
  // rejected for sinking into it.
  void ObserveCarried(const TableCarryConfig& config, uint32_t objects, uint32_t resting,
                      uint32_t sunk);

  TableCarryState state() const { return state_; }
  bool trusted() const { return state_ == TableCarryState::kCarried; }
  // The candidate or carried plane (valid unless kSearching).
  const RigidTransform& left_T_table() const { return left_T_table_; }
  uint32_t agreeing() const { return agreeing_; }       // estimates in a row that agreed
  uint32_t misfits() const { return misfits_; }         // misfits in a row while carried
  uint32_t carried_frames() const { return carried_; }  // frames carried since the last check
  uint32_t drops() const { return drops_; }             // planes dropped since Reset()

 private:
  // Starts confirming `plane` (one agreeing estimate).
  void Candidate(const RigidTransform& plane);
  // The candidate averaged with an agreeing estimate (running mean of normal and height).
  void Merge(const RigidTransform& plane);

  TableCarryState state_ = TableCarryState::kSearching;
  RigidTransform left_T_table_;
  uint32_t agreeing_ = 0;
  uint32_t misfits_ = 0;
  uint32_t carried_ = 0;
  uint32_t drops_ = 0;
};

}  // namespace sh
