// The vote of 2-D geometric hashing (thesis 2.2.3, 6.2) over an aspect table: for one scene
// basis frame, every other scene corner and line is expressed in hash coordinates and looked up
// in the table's bins; each model entry nearby receives the Gaussian vote exp(-d^2 / sigma^2)
// of its image distance d (eqs. 2.10, 6.1: hash distances converted with the frame's metric),
// from the fixed-point vote table, at most one (the best) per scene basis. A model basis's
// normalised vote is its point votes over its point entries plus its line votes over its line
// entries, in [0, 2].
//
// The per-entry and per-basis counters are one block taken at Init, sized by the table's entry
// and basis counts (docs/memory.md); nothing is allocated per vote.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "recog/base/init_block.hpp"
#include "recog/base/status.hpp"
#include "recog/hashing/vote_lut.hpp"
#include "recog/mono/frame2d.hpp"
#include "tables/aspect_view.hpp"

namespace sh {

// A scene corner in ideal (undistorted) image coordinates, pixels.
struct ScenePoint2d {
  Eigen::Vector2f xy{0, 0};
};

// A scene line in ideal image coordinates: a point, a unit direction, and the extent of its
// edge support along the direction (from the point).
struct SceneLine2d {
  Eigen::Vector2f point{0, 0};
  Eigen::Vector2f dir{1, 0};
  float t0 = 0, t1 = 0;  // supported extent: point + t dir for t in [t0, t1]
};

struct VoterConfig {
  // Vote widths (thesis 6.4.3: 5 px for corners, 3 px for lines). Wider here: the aspect grid
  // is 10 degrees apart, and a view between two aspects moves corners by several pixels.
  float sigma_point_px = 6.0f;
  float sigma_line_px = 6.0f;
  // A scene line looks up model segments whose direction is within this angle of its own
  // (similarity tables; affine maps do not keep angles, so all directions are looked up there).
  float line_angle_window_deg = 10.0f;
  // Model segments vote for a scene line when their centre lies along its supported extent,
  // lengthened at both ends by this (or half the extent, if more): an edge seen only in part
  // still has its centre near the part seen (thesis: the infinite line).
  float line_extent_margin_px = 20.0f;
};

struct AspectHypothesis {
  uint32_t basis = 0;  // model basis (AspectTableView::basis)
  float vote = 0.0f;   // normalised, [0, 2]
};

// The scene features that vote (null masks: all active).
struct VoteScene {
  const ScenePoint2d* points = nullptr;
  const uint8_t* point_active = nullptr;
  int n_points = 0;
  const SceneLine2d* lines = nullptr;
  const uint8_t* line_active = nullptr;
  int n_lines = 0;
};

// One scene basis: its frame, the points that made it (they do not vote), the normalised vote a
// hypothesis needs, and the range of basis keys (SetBasisKeys) that may receive votes.
struct VoteRequest {
  Frame2d frame;
  int exclude[3] = {-1, -1, -1};
  int n_exclude = 0;
  float threshold = 0.0f;
  float key_lo = -INFINITY, key_hi = INFINITY;
  // Scene features farther than this from the frame's origin (image units) do not vote: they
  // cannot belong to an object of the size the key range allows.
  float reach = INFINITY;
};

// Counts of one vote, for benchmarks and tuning.
struct VoteCounts {
  uint32_t point_lookups = 0, line_lookups = 0;  // scene features looked up
  uint32_t point_entries = 0, line_entries = 0;  // model entries compared
};

class AspectVoter {
 public:
  Status Init(const AspectTableView& table, const VoterConfig& config);
  const AspectTableView& table() const { return table_; }
  const VoterConfig& config() const { return config_; }

  // A key per model basis (e.g. its scale): only bases whose key lies in the request's
  // [key_lo, key_hi] receive votes; NaN never does. Null (default): every basis. The array must
  // outlive the voter's use of it.
  void SetBasisKeys(const float* keys) { basis_keys_ = keys; }

  // Votes for one scene basis. Writes the best hypotheses with a normalised vote of at least
  // request.threshold, best first, and returns their number (at most max_out).
  int Vote(const VoteScene& scene, const VoteRequest& request, AspectHypothesis* out, int max_out,
           VoteCounts* counts = nullptr);

  // The normalised vote a basis received in the last Vote() (0 if none).
  float LastVote(uint32_t basis) const;

  // Bytes of counters a voter needs for `table` (any alignment of the block).
  static size_t CounterBytes(const AspectTableView& table);
  // Sets this voter up as `like` (its table, configuration and basis keys) with its counters
  // carved from `size` bytes at `bytes`, memory that another stage lends while it is idle: it
  // is neither allocated nor freed here, and may hold anything (the stamps are cleared). Until
  // the next Init() or BorrowCounters(), the block must stay lent and `like`'s table and keys
  // valid. Errors (this voter cannot vote then, ready() false): `like` cannot vote, the block is
  // smaller than CounterBytes(like.table()).
  Status BorrowCounters(const AspectVoter& like, uint8_t* bytes, size_t size);
  // Whether Vote() may be called: Init() or BorrowCounters() succeeded.
  bool ready() const { return point_stamp_ != nullptr; }

 private:
  int StripRows(const Grid2d& g, const Eigen::Vector2f& n, float lo, float hi,
                const Eigen::Vector2f& u, float a0, float a1);
  void NextStamp();
  void AddPointVote(uint32_t entry, uint16_t vote);
  void AddLineVote(uint32_t entry, uint16_t vote);
  // The parts of Vote(): the scene points' votes, the scene lines' votes (each line prepared
  // by ScanLine; both counted into `counts`), and the best bases voted for.
  struct VoteSpan;
  struct LineScan;
  bool ScanLine(const SceneLine2d& line, const VoteRequest& request, const VoteSpan& span,
                LineScan* out);
  void VotePoints(const VoteScene& scene, const VoteRequest& request, const VoteSpan& span,
                  VoteCounts* counts);
  void VoteLines(const VoteScene& scene, const VoteRequest& request, const VoteSpan& span,
                 VoteCounts* counts);
  int BestHypotheses(float threshold, AspectHypothesis* out, int max_out) const;

  AspectTableView table_;
  VoterConfig config_;
  VoteTable lut_;
  const float* basis_keys_ = nullptr;
  float inv_sigma2_point_ = 0, inv_sigma2_line_ = 0;

  // Bytes of the counters' block for a table of that many entries and bases.
  static size_t BytesFor(uint32_t point_entries, uint32_t line_entries, uint32_t bases);
  // Takes (or, at the same size, clears) the counters' block for the table's counts.
  Status AllocateCounters();
  // Points the counters into `data` (`bytes` long), in the layout BytesFor sizes; false when it
  // is too small.
  bool CarveCounters(uint8_t* data, size_t bytes);

  uint16_t stamp_ = 0;
  // Carved from block_ at Init: table_.point_entry_count(), line_entry_count() and
  // basis_count() entries.
  InitBlock block_;
  uint16_t* point_stamp_ = nullptr;
  uint16_t* point_best_ = nullptr;
  uint16_t* line_stamp_ = nullptr;
  uint16_t* line_best_ = nullptr;
  uint16_t* basis_stamp_ = nullptr;
  uint32_t* basis_point_sum_ = nullptr;
  uint32_t* basis_line_sum_ = nullptr;
  uint32_t* touched_ = nullptr;
  uint32_t n_touched_ = 0;
  // The entry and basis counts the block was carved for: reused only for the same three.
  uint32_t carved_points_ = 0, carved_lines_ = 0, carved_bases_ = 0;
  // The counters lie in a block lent by another stage (BorrowCounters), not in block_.
  bool borrowed_ = false;
  // Rows of line-centre bins crossed by the current scene line's strip.
  uint16_t row_y_[kMaxAspectGridSide], row_x0_[kMaxAspectGridSide], row_x1_[kMaxAspectGridSide];
};

}  // namespace sh
