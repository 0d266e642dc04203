#include "recog/hashing/recognizer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "recog/model/model_features.hpp"

namespace sh {
namespace {

inline bool TestBit(const uint8_t* bits, uint16_t i) { return (bits[i >> 3] >> (i & 7)) & 1u; }
inline void SetBit(uint8_t* bits, uint16_t i) { bits[i >> 3] |= uint8_t(1u << (i & 7)); }

// Decoding of table values (table_format.hpp): Q10.6 mm.
constexpr float kMmPerRaw = 1.0f / 64.0f;

RigidTransform BasisTransform(const BasisRecord& r) {
  RigidTransform T;
  T.R = Eigen::Map<const Eigen::Matrix<float, 3, 3, Eigen::RowMajor>>(r.basis_T_model);
  T.t_mm = {r.basis_T_model[9], r.basis_T_model[10], r.basis_T_model[11]};
  return T;
}

// Bin index range [lo, hi] of a grid covering [v - r, v + r] on one axis; false if disjoint.
inline bool BinRange(const GridGeometry& g, int axis, float v, float r, int* lo, int* hi) {
  const float inv = 1.0f / g.bin_mm;
  const float a = (v - r - g.min_mm[axis]) * inv, b = (v + r - g.min_mm[axis]) * inv;
  if (b < 0.0f || a >= float(g.dims[axis])) return false;
  *lo = std::max(0, int(a));
  *hi = std::min(int(g.dims[axis]) - 1, int(b));
  return true;
}

// The x-bins of row (y, z) that intersect the ball of radius r around c: the neighbourhood is a
// ball, so rows and row ends outside it are skipped (about half of the bounding cube's bins).
inline bool RowRangeInBall(const GridGeometry& g, const Eigen::Vector3f& c, float r, int y, int z,
                           int* x_lo, int* x_hi) {
  auto slab_distance = [&g](float v, int axis, int i) {
    const float lo = g.min_mm[axis] + float(i) * g.bin_mm, hi = lo + g.bin_mm;
    return v < lo ? lo - v : (v > hi ? v - hi : 0.0f);
  };
  const float dy = slab_distance(c.y(), 1, y), dz = slab_distance(c.z(), 2, z);
  const float rest = r * r - dy * dy - dz * dz;
  if (rest < 0.0f) return false;
  return BinRange(g, 0, c.x(), std::sqrt(rest), x_lo, x_hi);
}

}  // namespace

bool SceneSupportVerifier::Verify(const Model& model, const Vector<RecognizedObject>& accepted,
                                  RecognizedObject& candidate) {
  // Points and lines are scored separately: a pose held by lines alone (or points alone) is
  // under-determined in ways clutter can satisfy.
  // Of the features hashing uses: a part's curved surfaces add none (model_features.hpp).
  const ModelFeatures features = FeaturesOf(model);
  const float points = float(candidate.matched_points) / float(std::max(1, features.n_corners()));
  const float lines = float(candidate.matched_lines) / float(std::max(1, features.n_lines()));
  candidate.verify_score[0] = points;
  candidate.verify_score[1] = lines;
  // Fractions, not counts: in 3-D alone a larger model around a fragment would win by size.
  candidate.verify_evidence = points + lines;
  return 0.5f * (points + lines) >= min_fraction_ && candidate.matched_points >= 3 &&
         candidate.matched_lines >= 3 &&
         candidate.matched_points + candidate.matched_lines >= min_features_;
}

Status Recognizer::Init(const TableView& table, const RecognizerConfig& config) {
  if (!(config.sigma_point_mm > 0.0f) || !(config.sigma_line_mm > 0.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "vote widths must be positive");
  }
  if (!(config.vote_threshold >= 0.0f && config.vote_threshold <= 2.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "vote threshold %g outside [0, 2]",
                         double(config.vote_threshold));
  }
  if (config.hypotheses_per_basis < 1 ||
      config.hypotheses_per_basis > int(kMaxHypothesesPerBasis)) {
    return Status::Error(StatusCode::kInvalidArgument, "hypotheses per basis must be 1..%zu",
                         kMaxHypothesesPerBasis);
  }
  if (config.compete_bases < 0 || config.compete_bases > kMaxCompeteBases) {
    return Status::Error(StatusCode::kInvalidArgument, "competing bases must be 0..%d",
                         kMaxCompeteBases);
  }
  // A challenger must explain at least as much as the object: margins of 0 .. 1.
  if (!(config.compete_evidence_margin >= 0.0f && config.compete_evidence_margin <= 1.0f) ||
      !(config.compete_score_margin >= 0.0f && config.compete_score_margin <= 1.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "competition margins must be 0..1 (got evidence %g, score %g)",
                         double(config.compete_evidence_margin),
                         double(config.compete_score_margin));
  }
  if (!(config.compete_vote_factor > 0.0f && config.compete_vote_factor <= 1.0f) ||
      config.compete_extra_matches < 0) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "competition vote factor must be in (0, 1] and extra matches >= 0 (got "
                         "%g, %d)",
                         double(config.compete_vote_factor), config.compete_extra_matches);
  }
  if (!(config.defer_below_score >= 0.0f && config.defer_below_score <= 1.0f)) {
    return Status::Error(StatusCode::kInvalidArgument, "defer_below_score must be 0..1 (got %g)",
                         double(config.defer_below_score));
  }
  // The spread's cells: a penalty of 0 or more, cells of 1 mm to 10 m (finite).
  if (!(config.basis_cell_rank_penalty >= 0.0f && config.basis_cell_rank_penalty <= 1e6f) ||
      !(config.basis_cell_size_mm >= 1.0f && config.basis_cell_size_mm <= 10000.0f)) {
    return Status::Error(StatusCode::kInvalidArgument,
                         "basis cell penalty must be 0..1e6 and the cell 1..10000 mm (got %g, %g)",
                         double(config.basis_cell_rank_penalty), double(config.basis_cell_size_mm));
  }
  table_ = table;
  config_ = config;
  // Reach of the model entries from their basis origins (plus the vote support), for the
  // neighbourhood of a scene basis.
  float point_reach = 0.0f, line_reach = 0.0f;
  for (uint32_t i = 0; i < table.point_entry_count(); ++i) {
    const PointEntry& e = table.point_entries()[i];
    point_reach = std::max(point_reach, Eigen::Vector3f(e.x, e.y, e.z).norm() * kMmPerRaw);
  }
  for (uint32_t i = 0; i < table.line_entry_count(); ++i) {
    const LineEntry& e = table.line_entries()[i];
    line_reach = std::max(line_reach, Eigen::Vector3f(e.cx, e.cy, e.cz).norm() * kMmPerRaw +
                                          0.5f * float(e.length) * kMmPerRaw);
  }
  point_reach_mm_ = point_reach + 2.0f * config.sigma_point_mm;
  line_reach_mm_ = line_reach + 2.0f * config.sigma_line_mm;
  inv_sigma2_point_ = 1.0f / (config.sigma_point_mm * config.sigma_point_mm);
  inv_sigma2_line_ = 1.0f / (config.sigma_line_mm * config.sigma_line_mm);
  // Unbuilt (too large a table, or off), the look-ups visit every entry of the neighbourhood.
  if (config.line_direction_index) {
    line_index_.Build(table, 12.0f * float(kVoteCutoff) / inv_sigma2_line_);
  } else {
    line_index_.Clear();
  }
  for (int t = 0; t < kMaxVoteThreads; ++t) {
    VoteScratch* v = t == 0 ? &scratch_ : other_scratch_[t - 1].get();
    if (v == nullptr) continue;
    std::memset(v->point_vote, 0, sizeof(v->point_vote));
    std::memset(v->line_vote, 0, sizeof(v->line_vote));
    std::memset(v->basis_point_sum, 0, sizeof(v->basis_point_sum));
    std::memset(v->basis_line_sum, 0, sizeof(v->basis_line_sum));
    std::memset(v->basis_touched, 0, sizeof(v->basis_touched));
  }
  scratch_lent_bytes_ = 0;
  ahead_.Clear();
  return Status::Ok();
}

Recognizer::LentMemory Recognizer::LendVoteScratch(size_t bytes) {
  if (other_scratch_[0] == nullptr || bytes > sizeof(VoteScratch)) return {};
  // Lent again before a search: the bytes written under the first loan are cleared too.
  scratch_lent_bytes_ = std::max(scratch_lent_bytes_, bytes);
  return {reinterpret_cast<uint8_t*>(other_scratch_[0].get()), bytes};
}

Status Recognizer::SetParallel(const ParallelFor& parallel, int threads) {
  parallel_ = {};
  vote_threads_ = 1;
  ahead_.Clear();
  if (!parallel.concurrent() || threads < 2) return Status::Ok();
  threads = std::min(threads, kMaxVoteThreads);
  for (int t = 1; t < threads; ++t) {
    if (other_scratch_[t - 1] != nullptr) continue;
    // Zero-filled: the vote arrays' invariant (all zero between rounds) holds from the start.
    other_scratch_[t - 1] = MakeZeroed<VoteScratch>();
    if (other_scratch_[t - 1] == nullptr) {
      return Status::Error(StatusCode::kUnavailable,
                           "no memory for the vote arrays of %d threads (%zu bytes each)", threads,
                           sizeof(VoteScratch));
    }
  }
  parallel_ = parallel;
  vote_threads_ = threads;
  return Status::Ok();
}

void Recognizer::PrepareScene(const Scene& scene) {
  scene_ = &scene;
  const int np = int(scene.points.size()), nl = int(scene.lines.size());
  for (int i = 0; i < np; ++i) point_active_[i] = scene.points[i].p_mm.allFinite();
  std::fill(point_claimed_, point_claimed_ + np, uint8_t{0});
  std::fill(line_claimed_, line_claimed_ + nl, uint8_t{0});
  Eigen::Vector3f* positions = grid_scratch_;
  for (int i = 0; i < np; ++i) positions[i] = scene.points[i].p_mm;
  point_grid_.Build(positions, np, 5.0f);
  for (int i = 0; i < nl; ++i) {
    const SceneLine& l = scene.lines[i];
    const float length = l.length_mm();
    line_active_[i] = l.a_mm.allFinite() && l.b_mm.allFinite() && length > 1.0f;
    line_dir_[i] =
        line_active_[i] ? Eigen::Vector3f((l.b_mm - l.a_mm) / length) : Eigen::Vector3f::UnitX();
  }
  state_ = {&scene, point_active_, line_active_, line_dir_, &point_grid_};
  topology_.Build(state_, config_.connect_tolerance_mm, config_.junction_reach_mm, grid_scratch_);
  std::memset(used_left_point_, 0, sizeof(used_left_point_));
  std::memset(used_right_point_, 0, sizeof(used_right_point_));
  std::memset(used_left_line_, 0, sizeof(used_left_line_));
  std::memset(used_right_line_, 0, sizeof(used_right_line_));
  BasisCandidates::Policy policy;
  policy.order = config_.order;
  policy.random_seed = config_.random_seed;
  policy.connect_tolerance_mm = config_.connect_tolerance_mm;
  policy.cell_rank_penalty = config_.basis_cell_rank_penalty;
  policy.cell_size_mm = config_.basis_cell_size_mm;
  candidates_.Generate(state_, topology_, table_.hash_function(), table_.limits(), policy);
}

bool Recognizer::SceneBasisFrame(const SceneBasis& b, RigidTransform* basis_T_cam,
                                 Eigen::Vector3f* shape_point) const {
  const Scene& s = *scene_;
  const HashFunction hf = table_.hash_function();
  const BasisLimits limits = table_.limits();
  if (UsesThreePoints(hf)) {
    const Eigen::Vector3f &p0 = s.points[b.f[0]].p_mm, &p1 = s.points[b.f[1]].p_mm,
                          &p2 = s.points[b.f[2]].p_mm;
    if (!ThreePointFrame(hf, p0, p1, p2, limits, basis_T_cam)) return false;
    *shape_point = TriangleShapePoint(p0, p1, p2);
    return true;
  }
  if (hf == HashFunction::kTwoLines) {
    return TwoLineFrame({s.lines[b.f[0]].a_mm, line_dir_[b.f[0]]},
                        {s.lines[b.f[1]].a_mm, line_dir_[b.f[1]]}, limits, basis_T_cam);
  }
  return LinePointFrame(hf, {s.lines[b.f[0]].a_mm, line_dir_[b.f[0]]}, s.points[b.f[1]].p_mm,
                        limits, basis_T_cam);
}

void Recognizer::VotePoint(const Eigen::Vector3f& q, VoteScratch& scratch) const {
  const GridGeometry& g = table_.point_grid();
  const float r = 2.0f * config_.sigma_point_mm;  // votes beyond 2 sigma are cut (vote_lut.hpp)
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    if (!BinRange(g, a, q[a], r, &lo[a], &hi[a])) return;
  }
  const PointEntry* base = table_.point_entries();
  const uint32_t* offsets = table_.point_bin_offsets();
  for (int z = lo[2]; z <= hi[2]; ++z) {
    for (int y = lo[1]; y <= hi[1]; ++y) {
      int x_lo = 0, x_hi = 0;
      if (!RowRangeInBall(g, q, r, y, z, &x_lo, &x_hi)) continue;
      const uint32_t row = (uint32_t(z) * g.dims[1] + uint32_t(y)) * g.dims[0];
      // Bins of one row are contiguous in the entry array: one range covers x = lo..hi.
      const uint32_t begin = offsets[row + x_lo], end = offsets[row + x_hi + 1];
      for (uint32_t e = begin; e < end; ++e) {
        const PointEntry& p = base[e];
        const float dx = float(p.x) * kMmPerRaw - q.x();
        const float dy = float(p.y) * kMmPerRaw - q.y();
        const float dz = float(p.z) * kMmPerRaw - q.z();
        const uint16_t v = votes_lut_.Vote(dx * dx + dy * dy + dz * dz, inv_sigma2_point_);
        if (v > scratch.point_vote[e]) {
          if (scratch.point_vote[e] == 0) scratch.touched_points[scratch.n_touched_points++] = e;
          scratch.point_vote[e] = v;
        }
      }
    }
  }
}

// One line entry's vote for the scene line, kept if it beats the entry's best so far; the
// entries the look-up's tests rule out are skipped.
inline void Recognizer::VoteLineEntry(const LineDirectionIndex::Entry& l, const LineLookUp& q,
                                      VoteScratch& scratch) const {
  if (!q.RulesOut(l)) VoteKeptLineEntry(l, q, scratch);
}

// The vote of an entry the look-up's tests kept.
inline void Recognizer::VoteKeptLineEntry(const LineDirectionIndex::Entry& l, const LineLookUp& q,
                                          VoteScratch& scratch) const {
  const Eigen::Vector3f c(l.cx, l.cy, l.cz), u(l.ux, l.uy, l.uz);
  const uint16_t vote =
      votes_lut_.Vote(SegmentLineDistance2(c, u, l.length_mm, q.s, q.v), inv_sigma2_line_);
  const uint32_t e = l.table_index;
  if (vote > scratch.line_vote[e]) {
    if (scratch.line_vote[e] == 0) scratch.touched_lines[scratch.n_touched_lines++] = e;
    scratch.line_vote[e] = vote;
  }
}

void Recognizer::VoteLine(const Eigen::Vector3f& s, const Eigen::Vector3f& v,
                          VoteScratch& scratch) const {
  const GridGeometry& g = table_.line_grid();
  const float r = config_.line_neighbourhood_factor * 2.0f * config_.sigma_line_mm;
  int lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    if (!BinRange(g, a, s[a], r, &lo[a], &hi[a])) return;
  }
  const LineLookUp q = LineLookUp::For(s, v, inv_sigma2_line_);

  const LineEntry* base = table_.line_entries();
  const uint32_t* offsets = table_.line_bin_offsets();
  const bool indexed = line_index_.built();
  const uint64_t live = indexed ? line_index_.LiveClasses(v) : 0u;
  const uint32_t first_new = scratch.n_touched_lines;
  for (int z = lo[2]; z <= hi[2]; ++z) {
    for (int y = lo[1]; y <= hi[1]; ++y) {
      int x_lo = 0, x_hi = 0;
      if (!RowRangeInBall(g, s, r, y, z, &x_lo, &x_hi)) continue;
      const uint32_t row = (uint32_t(z) * g.dims[1] + uint32_t(y)) * g.dims[0];
      const uint32_t first = row + uint32_t(x_lo), last = row + uint32_t(x_hi);
      if (indexed) {
        // Only the live classes with entries in these bins: most (class, row) ranges are empty.
        for (uint64_t m = live & line_index_.ClassesIn(first, last); m != 0; m &= m - 1) {
          const int c = __builtin_ctzll(m);
          const uint32_t end = line_index_.end(c, last);
          for (uint32_t i = line_index_.begin(c, first); i < end; i += kFloat4Lanes) {
            unsigned kept = q.KeptLanes(line_index_.LanesAt(i));
            if (end - i < uint32_t(kFloat4Lanes)) kept &= (1u << (end - i)) - 1u;
            for (; kept != 0; kept &= kept - 1) {
              VoteKeptLineEntry(line_index_.entry(i + uint32_t(__builtin_ctz(kept))), q, scratch);
            }
          }
        }
        continue;
      }
      const uint32_t begin = offsets[first], end = offsets[last + 1];
      for (uint32_t e = begin; e < end; ++e) VoteLineEntry(DecodeLineEntry(base[e], e), q, scratch);
    }
  }
  if (indexed) {
    // Without the index the entries are visited in table order, so first touched in ascending
    // order; restore that order, on which the order of the model bases (and ties) depends.
    std::sort(scratch.touched_lines + first_new, scratch.touched_lines + scratch.n_touched_lines);
  }
}

int Recognizer::VoteForBasis(const SceneBasis& b, Vector<Hypothesis>& out, float* best_per_model) {
  return Vote(b, scratch_, out, best_per_model);
}

int Recognizer::VoteInTurn(uint32_t index, const SceneBasis& b, uint32_t most,
                           Vector<Hypothesis>& out) {
  if (const auto* voted = ahead_.Find(index)) {
    out = *voted;
    return int(out.size());
  }
  if (!parallel_.concurrent()) return Vote(b, scratch_, out, nullptr);
  // This basis and the next active ones of the pass, voted on the scene as it is now; the
  // search only removes features, so the bases skipped here stay inactive until they come. No
  // more than the search may still try (its budget and fruitless limit), so that it stops where
  // the one-thread search stops, without votes thrown away.
  const uint32_t gathered = ahead_.Gather(
      index, candidates_.count(), most, [this](uint32_t j) { return BasisActive(candidates_[j]); });
  if (gathered == 1) return Vote(b, scratch_, out, nullptr);
  out = ahead_.ComputeAll(
      parallel_, vote_threads_,
      [](void* self, int thread, AheadVotes::Entry& e) {
        auto* r = static_cast<Recognizer*>(self);
        (void)r->Vote(r->candidates_[e.index], r->ScratchOf(thread), e.result, nullptr);
      },
      this);
  return int(out.size());
}

int Recognizer::Vote(const SceneBasis& b, VoteScratch& v, Vector<Hypothesis>& out,
                     float* best_per_model, float threshold) const {
  if (threshold < 0.0f) threshold = config_.vote_threshold;
  out.clear();
  if (best_per_model != nullptr) std::fill(best_per_model, best_per_model + kMaxTableModels, 0.0f);
  RigidTransform basis_T_cam;
  Eigen::Vector3f shape_point;
  if (!SceneBasisFrame(b, &basis_T_cam, &shape_point)) return 0;
  const Scene& s = *scene_;
  const HashFunction hf = table_.hash_function();
  const bool three_points = UsesThreePoints(hf), line_point = UsesLinePoint(hf);

  v.n_touched_points = v.n_touched_lines = 0;
  // Only features near the basis origin can match a model feature: every model entry lies
  // within reach_mm of its basis origin. Scene lines vote only if their supported segment
  // comes that close; their infinite extension elsewhere is not evidence for this object.
  const Eigen::Vector3f origin = basis_T_cam.Inverse().t_mm;
  point_grid_.ForEachNearByScan(origin, point_reach_mm_, [&](int j) {
    if (!point_active_[j]) return;
    if (three_points && (j == b.f[0] || j == b.f[1] || j == b.f[2])) return;
    if (line_point && j == b.f[1]) return;
    VotePoint(basis_T_cam * s.points[j].p_mm, v);
  });
  if (three_points) VotePoint(shape_point, v);
  const float line_reach2 = line_reach_mm_ * line_reach_mm_;
  for (size_t j = 0; j < s.lines.size(); ++j) {
    if (!line_active_[j]) continue;
    if (line_point && j == b.f[0]) continue;
    const SceneLine& l = s.lines[j];
    const Eigen::Vector3f ao = origin - l.a_mm;
    const float t = std::clamp(ao.dot(line_dir_[j]), 0.0f, l.length_mm());
    if ((ao - t * line_dir_[j]).squaredNorm() > line_reach2) continue;
    const Eigen::Vector3f a = basis_T_cam * l.a_mm;
    const Eigen::Vector3f dir = basis_T_cam.Rotate(line_dir_[j]);
    VoteLine(SupportVector(a, dir), dir, v);
  }

  // Sum the best vote of every touched entry into its model basis, resetting as we go.
  v.n_touched_bases = 0;
  const PointEntry* points = table_.point_entries();
  const LineEntry* lines = table_.line_entries();
  auto touch = [&v](uint16_t basis) {
    if (!v.basis_touched[basis]) {
      v.basis_touched[basis] = 1;
      v.touched_bases[v.n_touched_bases++] = basis;
    }
  };
  for (uint32_t i = 0; i < v.n_touched_points; ++i) {
    const uint32_t e = v.touched_points[i];
    v.basis_point_sum[points[e].basis] += v.point_vote[e];
    touch(points[e].basis);
    v.point_vote[e] = 0;
  }
  for (uint32_t i = 0; i < v.n_touched_lines; ++i) {
    const uint32_t e = v.touched_lines[i];
    v.basis_line_sum[lines[e].basis] += v.line_vote[e];
    touch(lines[e].basis);
    v.line_vote[e] = 0;
  }

  // Keep the best hypotheses_per_basis model bases at or above the threshold.
  const int k_max = config_.hypotheses_per_basis;
  float best_vote[kMaxHypothesesPerBasis];
  uint16_t best_basis[kMaxHypothesesPerBasis];
  int n_best = 0;
  for (uint32_t i = 0; i < v.n_touched_bases; ++i) {
    const uint16_t bi = v.touched_bases[i];
    const BasisRecord& r = table_.basis(bi);
    // Sums are UQ0.16 votes: divide by 65535 for the vote value, by the entry counts to normalise.
    const float vote =
        (r.n_point_entries ? float(v.basis_point_sum[bi]) / (65535.0f * r.n_point_entries) : 0.0f) +
        (r.n_line_entries ? float(v.basis_line_sum[bi]) / (65535.0f * r.n_line_entries) : 0.0f);
    v.basis_point_sum[bi] = v.basis_line_sum[bi] = 0;
    v.basis_touched[bi] = 0;
    if (best_per_model != nullptr)
      best_per_model[r.model] = std::max(best_per_model[r.model], vote);
    if (vote < threshold || !((config_.model_mask >> r.model) & 1u)) continue;
    int pos = n_best < k_max ? n_best++ : k_max;
    if (pos == k_max && vote <= best_vote[k_max - 1]) continue;
    if (pos == k_max) pos = k_max - 1;
    while (pos > 0 && best_vote[pos - 1] < vote) {
      best_vote[pos] = best_vote[pos - 1];
      best_basis[pos] = best_basis[pos - 1];
      --pos;
    }
    best_vote[pos] = vote;
    best_basis[pos] = bi;
  }
  const RigidTransform cam_T_basis = basis_T_cam.Inverse();
  for (int i = 0; i < n_best; ++i) {
    const BasisRecord& r = table_.basis(best_basis[i]);
    Hypothesis h;
    h.model = r.model;
    h.model_basis = best_basis[i];
    h.scene_basis = b;
    h.vote = best_vote[i];
    h.cam_T_model = cam_T_basis * BasisTransform(r);
    if (!out.push_back(h)) break;
  }
  return int(out.size());
}

int Recognizer::ActiveFeatureCount() const {
  int active = 0;
  for (size_t j = 0; j < scene_->points.size(); ++j) active += point_active_[j];
  for (size_t j = 0; j < scene_->lines.size(); ++j) active += line_active_[j];
  return active;
}

bool Recognizer::BasisFlagged(const SceneBasis& b, const uint8_t* point_flag,
                              const uint8_t* line_flag) const {
  const HashFunction hf = table_.hash_function();
  if (UsesThreePoints(hf)) return point_flag[b.f[0]] && point_flag[b.f[1]] && point_flag[b.f[2]];
  if (hf == HashFunction::kTwoLines) return line_flag[b.f[0]] && line_flag[b.f[1]];
  return line_flag[b.f[0]] && point_flag[b.f[1]];
}

bool Recognizer::BasisActive(const SceneBasis& b) const {
  return BasisFlagged(b, point_active_, line_active_);
}

void Recognizer::RemoveObjectFeatures(const Model& model, const Correspondences& c) {
  const Scene& s = *scene_;
  auto mark = [](uint8_t* bits, uint16_t id) {
    if (id != kNoFeature2d) SetBit(bits, id);
  };
  for (int i = 0; i < model.n_corners; ++i) {
    const int j = c.point_of_corner[i];
    if (j < 0) continue;
    point_active_[j] = 0;
    mark(used_left_point_, s.points[j].source.left);
    mark(used_right_point_, s.points[j].source.right);
  }
  for (int e = 0; e < model.n_edges; ++e) {
    const int j = c.line_of_edge[e];
    if (j < 0) continue;
    line_active_[j] = 0;
    mark(used_left_line_, s.lines[j].source.left);
    mark(used_right_line_, s.lines[j].source.right);
  }
  auto shares = [](const uint8_t* left, const uint8_t* right, const FeatureSource& src) {
    return (src.left != kNoFeature2d && TestBit(left, src.left)) ||
           (src.right != kNoFeature2d && TestBit(right, src.right));
  };
  for (size_t j = 0; j < s.points.size(); ++j) {
    if (point_active_[j] && shares(used_left_point_, used_right_point_, s.points[j].source))
      point_active_[j] = 0;
  }
  for (size_t j = 0; j < s.lines.size(); ++j) {
    if (line_active_[j] && shares(used_left_line_, used_right_line_, s.lines[j].source))
      line_active_[j] = 0;
  }
}

bool Recognizer::TooCloseToAccepted(const RigidTransform& cam_T_model,
                                    const Vector<RecognizedObject>& objects) const {
  const float d2 = config_.min_object_separation_mm * config_.min_object_separation_mm;
  for (const RecognizedObject& o : objects) {
    if ((o.cam_T_model.t_mm - cam_T_model.t_mm).squaredNorm() < d2) return true;
  }
  return false;
}

using Outcome = SearchObserver::Outcome;

bool ChallengerClearlyBetter(const RecognizedObject& challenger, const RecognizedObject& object,
                             const RecognizerConfig& config) {
  const float margin = config.compete_score_margin;
  const float* c = challenger.verify_score;
  const float* o = object.verify_score;
  if (!(c[0] + c[1] >= o[0] + o[1] + 2.0f * margin)) return false;
  const float evidence_margin = config.compete_evidence_margin;
  if (challenger.verify_evidence >= (1.0f + evidence_margin) * object.verify_evidence) {
    return c[0] >= o[0] - margin && c[1] >= o[1] - margin;
  }
  return challenger.verify_evidence >= (1.0f - evidence_margin) * object.verify_evidence &&
         c[0] >= o[0] && c[1] >= o[1];
}

bool Recognizer::Defer(const RecognizedObject& object, RecognitionStats& stats) {
  if (!(std::min(object.verify_score[0], object.verify_score[1]) < config_.defer_below_score)) {
    return false;
  }
  const float d2 = config_.min_object_separation_mm * config_.min_object_separation_mm;
  RecognizedObject* weakest = nullptr;
  for (RecognizedObject& held : deferred_) {
    if ((held.cam_T_model.t_mm - object.cam_T_model.t_mm).squaredNorm() < d2) {
      if (object.verify_evidence > held.verify_evidence) held = object;  // one per place
      return true;
    }
    if (weakest == nullptr || held.verify_evidence < weakest->verify_evidence) weakest = &held;
  }
  ++stats.deferred;
  if (!deferred_.full()) {
    (void)deferred_.push_back(object);
  } else if (object.verify_evidence > weakest->verify_evidence) {
    *weakest = object;
  }
  return true;
}

void Recognizer::AcceptDeferred(HypothesisVerifier& verifier, const Budget& budget,
                                Vector<RecognizedObject>& objects, RecognitionStats& stats) {
  std::sort(deferred_.begin(), deferred_.end(),
            [](const RecognizedObject& a, const RecognizedObject& b) {
              return a.verify_evidence > b.verify_evidence;
            });
  for (const RecognizedObject& held : deferred_) {
    if (objects.full() || (budget.max_objects != 0 && objects.size() >= budget.max_objects)) break;
    const Model& model = table_.model(held.model);
    if (TooCloseToAccepted(held.cam_T_model, objects) ||
        verifier.Interpenetrates(model, held, objects)) {
      continue;
    }
    // The objects accepted since may hide part of it.
    RecognizedObject object = held;
    if (!verifier.Verify(model, objects, object)) continue;
    object.instance = 0;
    for (const RecognizedObject& o : objects) object.instance += o.model == object.model;
    (void)objects.push_back(object);  // not full: checked above
    ++stats.accepted;
    ++stats.deferred_accepted;
    if (observer_) observer_->OnAccepted(stats.scene_bases_tried, object);
  }
}

void Recognizer::Evaluate(const Hypothesis& h, const RefineInput& refine_in,
                          const Vector<RecognizedObject>& objects, HypothesisVerifier& verifier,
                          int min_matched, Evaluated* out) const {
  const Model& model = table_.model(h.model);
  RefineInput in = refine_in;
  in.model = &model;
  const RefineResult refined = RefinePose(in, h.cam_T_model, config_.refine);
  RecognizedObject& candidate = out->candidate;
  candidate = RecognizedObject{};
  candidate.model = h.model;
  candidate.cam_T_model = refined.cam_T_model;
  candidate.vote = h.vote;
  candidate.fit_rms_mm = refined.rms_mm;
  out->too_close = TooCloseToAccepted(refined.cam_T_model, objects);
  out->enough = out->verified = false;
  if (out->too_close) return;
  // The verifier counts support within a tighter gate than refinement used: clutter near a
  // wrong pose easily falls within 2 sigma, rarely within 1.
  Correspondences tight;
  SelectCorrespondences(in, refined.cam_T_model,
                        config_.support_gate_sigmas * config_.sigma_point_mm, &tight);
  candidate.matched_points = uint16_t(tight.matched_points);
  candidate.matched_lines = uint16_t(tight.matched_lines);
  out->enough = tight.matched_points + tight.matched_lines >= min_matched;
  if (!out->enough) return;
  out->verified = verifier.Verify(model, objects, candidate);
  if (out->verified) out->matches = refined.matches;
}

bool Recognizer::Conclude(const Hypothesis& h, const Evaluated& e, uint32_t basis_number,
                          RecognitionStats& stats, RecognizedObject* candidate,
                          Correspondences* matches) const {
  *candidate = e.candidate;
  if (e.too_close) {
    if (observer_) observer_->OnHypothesis(basis_number, h, *candidate, Outcome::kTooClose);
    return false;
  }
  if (!e.enough) return false;
  ++stats.verifications;
  if (observer_) {
    observer_->OnHypothesis(basis_number, h, *candidate,
                            e.verified ? Outcome::kVerified : Outcome::kRejected);
  }
  if (e.verified) *matches = e.matches;
  return e.verified;
}

bool Recognizer::RefineAndVerify(const Hypothesis& h, uint32_t basis_number, RefineInput& refine_in,
                                 const Vector<RecognizedObject>& objects,
                                 HypothesisVerifier& verifier, RecognitionStats& stats,
                                 RecognizedObject* candidate, Correspondences* matches,
                                 int min_matched) {
  Evaluated e;
  Evaluate(h, refine_in, objects, verifier, min_matched, &e);
  return Conclude(h, e, basis_number, stats, candidate, matches);
}

bool Recognizer::EvaluateAhead(const Vector<Hypothesis>& hypotheses, const RefineInput& refine_in,
                               const Vector<RecognizedObject>& objects,
                               HypothesisVerifier& verifier, int min_matched) {
  if (!parallel_.concurrent() || hypotheses.size() < 2 || !verifier.ConcurrentVerify()) {
    return false;
  }
  struct Job {
    const Recognizer* self;
    const Vector<Hypothesis>* hypotheses;
    const RefineInput* refine_in;
    const Vector<RecognizedObject>* objects;
    HypothesisVerifier* verifier;
    int min_matched;
    Evaluated* out;
  } job{this, &hypotheses, &refine_in, &objects, &verifier, min_matched, evaluated_};
  parallel_(
      int(hypotheses.size()),
      [](void* context, int i) {
        const Job& j = *static_cast<const Job*>(context);
        j.self->Evaluate((*j.hypotheses)[size_t(i)], *j.refine_in, *j.objects, *j.verifier,
                         j.min_matched, &j.out[i]);
      },
      &job);
  return true;
}

bool Recognizer::RefineAndVerifyAt(const Vector<Hypothesis>& hypotheses, size_t i, bool ahead,
                                   uint32_t basis_number, RefineInput& refine_in,
                                   const Vector<RecognizedObject>& objects,
                                   HypothesisVerifier& verifier, RecognitionStats& stats,
                                   RecognizedObject* candidate, Correspondences* matches,
                                   int min_matched) {
  if (!ahead) {
    return RefineAndVerify(hypotheses[i], basis_number, refine_in, objects, verifier, stats,
                           candidate, matches, min_matched);
  }
  return Conclude(hypotheses[i], evaluated_[i], basis_number, stats, candidate, matches);
}

void Recognizer::MarkClaims(const Correspondences& matches, const Model& model, uint8_t claimed) {
  for (int i = 0; i < model.n_corners; ++i) {
    if (matches.point_of_corner[i] >= 0) point_claimed_[matches.point_of_corner[i]] = claimed;
  }
  for (int e = 0; e < model.n_edges; ++e) {
    if (matches.line_of_edge[e] >= 0) line_claimed_[matches.line_of_edge[e]] = claimed;
  }
}

int Recognizer::ChooseCompeteBases(uint32_t next, const Eigen::Vector3f& centre_mm,
                                   float radius2_mm2, const Correspondences& matches,
                                   const Model& model, uint32_t* chosen) {
  const int most = std::min(config_.compete_bases, kMaxCompeteBases);
  const uint32_t window_end = std::min(candidates_.count(), next + kCompeteScanBases);
  MarkClaims(matches, model, 1);
  // First the bases made only of the object's own matched features, anywhere in the rest of the
  // list (a larger model whose part the object fits shares exactly those, and its bases may rank
  // far behind); then the next bases near the object's centre.
  int n_chosen = 0;
  for (uint32_t j = next; j < candidates_.count() && n_chosen < most; ++j) {
    if (BasisActive(candidates_[j]) && BasisFlagged(candidates_[j], point_claimed_, line_claimed_))
      chosen[n_chosen++] = j;
  }
  for (uint32_t j = next; j < window_end && n_chosen < most; ++j) {
    const SceneBasis& b = candidates_[j];
    if (!BasisActive(b) || BasisFlagged(b, point_claimed_, line_claimed_)) continue;
    RigidTransform basis_T_cam;
    Eigen::Vector3f shape_point;
    if (!SceneBasisFrame(b, &basis_T_cam, &shape_point)) continue;
    if ((basis_T_cam.Inverse().t_mm - centre_mm).squaredNorm() > radius2_mm2) continue;
    chosen[n_chosen++] = j;
  }
  MarkClaims(matches, model, 0);
  return n_chosen;
}

void Recognizer::CompeteAtPlace(uint32_t next, uint32_t basis_number, RefineInput& refine_in,
                                const Vector<RecognizedObject>& objects,
                                HypothesisVerifier& verifier, RecognitionStats& stats,
                                RecognizedObject& best, Correspondences& best_matches) {
  const Model& accepted_model = table_.model(best.model);
  float radius2_mm2 = 0.0f;
  for (int i = 0; i < accepted_model.n_corners; ++i) {
    radius2_mm2 = std::max(radius2_mm2, accepted_model.corner(i).squaredNorm());
  }
  const Eigen::Vector3f centre_mm = best.cam_T_model.t_mm;
  const float place2_mm2 = config_.min_object_separation_mm * config_.min_object_separation_mm;
  // Scores of the object to beat; `best` changes when a challenger wins.
  const RecognizedObject first = best;
  bool replaced = false;
  uint32_t chosen[kMaxCompeteBases];
  const int n_chosen =
      ChooseCompeteBases(next, centre_mm, radius2_mm2, best_matches, accepted_model, chosen);
  Vector<Hypothesis, kMaxHypothesesPerBasis> hypotheses;
  // Bases voted ahead of their turn were voted at the search's threshold.
  const float threshold = config_.compete_vote_factor * config_.vote_threshold;
  const bool afresh = config_.compete_vote_factor < 1.0f;
  for (int c = 0; c < n_chosen; ++c) {
    const uint32_t j = chosen[c];
    const SceneBasis& b = candidates_[j];
    // With two threads or more the next bases were mostly voted ahead, on this same scene (an
    // acceptance follows, which drops them all).
    if (const auto* voted = afresh ? nullptr : ahead_.Find(j)) {
      hypotheses = *voted;
    } else {
      (void)Vote(b, scratch_, hypotheses, nullptr, threshold);
    }
    stats.hypotheses += uint32_t(hypotheses.size());
    // The challengers: other models at this place.
    Vector<Hypothesis, kMaxHypothesesPerBasis> challengers;
    for (const Hypothesis& h : hypotheses) {
      if (h.model == first.model) continue;
      if ((h.cam_T_model.t_mm - centre_mm).squaredNorm() >= place2_mm2) continue;
      (void)challengers.push_back(h);
    }
    const int min_matched =
        first.matched_points + first.matched_lines + config_.compete_extra_matches;
    const bool ahead = EvaluateAhead(challengers, refine_in, objects, verifier, min_matched);
    for (size_t i = 0; i < challengers.size(); ++i) {
      RecognizedObject candidate;
      Correspondences matches;
      // More 3-D support than the object (matched corners and edges) before the verifier is
      // asked.
      if (!RefineAndVerifyAt(challengers, i, ahead, basis_number, refine_in, objects, verifier,
                             stats, &candidate, &matches, min_matched)) {
        continue;
      }
      if ((candidate.cam_T_model.t_mm - centre_mm).squaredNorm() >= place2_mm2) continue;
      if (ChallengerClearlyBetter(candidate, first, config_) &&
          (!replaced || candidate.verify_evidence > best.verify_evidence)) {
        best = candidate;
        best_matches = matches;
        replaced = true;
      }
    }
  }
}

Status Recognizer::Recognize(const Scene& scene, HypothesisVerifier& verifier, const Budget& budget,
                             Vector<RecognizedObject>& objects, RecognitionStats* stats_out) {
  RecognitionStats stats;
  objects.clear();
  if (scratch_lent_bytes_ > 0) {
    // Written by a borrower: back to the all-zero state the votes rely on.
    std::memset(static_cast<void*>(other_scratch_[0].get()), 0, scratch_lent_bytes_);
    scratch_lent_bytes_ = 0;
  }
  PrepareScene(scene);
  ahead_.Clear();
  deferred_.clear();
  uint32_t cursor = 0;
  uint32_t fruitless = 0;
  uint32_t generated = candidates_.count();
  Vector<Hypothesis, kMaxHypothesesPerBasis> hypotheses;
  RefineInput refine_in;
  refine_in.scene = &scene;
  refine_in.point_active = point_active_;
  refine_in.line_active = line_active_;
  refine_in.point_grid = &point_grid_;
  refine_in.sigma_point_mm = config_.sigma_point_mm;
  refine_in.sigma_line_mm = config_.sigma_line_mm;
  for (;;) {
    if (stats.scene_bases_tried >= budget.max_scene_bases ||
        (budget.deadline_ns != 0 && budget.now_ns != nullptr &&
         budget.now_ns() >= budget.deadline_ns)) {
      stats.budget_exhausted = true;
      break;
    }
    if (cursor == candidates_.count()) {
      if (!candidates_.NextPass()) break;
      cursor = 0;
      ahead_.Clear();  // indices of the pass before
      generated += candidates_.count();
      if (candidates_.count() == 0) break;
    }
    const SceneBasis basis = candidates_[cursor++];
    if (!BasisActive(basis)) continue;
    if (ActiveFeatureCount() < config_.min_active_features) break;
    if (fruitless >= config_.max_fruitless_bases) break;
    if (budget.max_objects != 0 && objects.size() >= budget.max_objects) break;

    const uint32_t basis_number = stats.scene_bases_tried++;
    // The bases this search may still try, this one included (both limits were checked above).
    const uint32_t most =
        std::min(budget.max_scene_bases - basis_number, config_.max_fruitless_bases - fruitless);
    stats.hypotheses += VoteInTurn(cursor - 1, basis, most, hypotheses);
    ++fruitless;
    // Every hypothesis of this basis is refined and verified; the best supported one wins
    // (a partial view can fit a wrong model or a wrong orientation as well as the right one).
    RecognizedObject best;
    Correspondences best_matches;
    float best_support = -1.0f;
    // With two threads or more the hypotheses are evaluated together, then taken in turn.
    const bool ahead = EvaluateAhead(hypotheses, refine_in, objects, verifier, 0);
    for (size_t i = 0; i < hypotheses.size(); ++i) {
      RecognizedObject candidate;
      Correspondences matches;
      if (!RefineAndVerifyAt(hypotheses, i, ahead, basis_number, refine_in, objects, verifier,
                             stats, &candidate, &matches)) {
        continue;
      }
      const float support = candidate.verify_evidence;
      if (support > best_support) {
        best_support = support;
        best = candidate;
        best_matches = matches;
      }
    }
    if (best_support >= 0.0f) {
      if (config_.compete_bases > 0) {
        CompeteAtPlace(cursor, basis_number, refine_in, objects, verifier, stats, best,
                       best_matches);
      }
      if (Defer(best, stats)) continue;
      for (const RecognizedObject& o : objects) best.instance += o.model == best.model;
      if (!objects.push_back(best)) {
        stats.objects_full = true;
        break;
      }
      ++stats.accepted;
      if (observer_) observer_->OnAccepted(basis_number, best);
      fruitless = 0;
      RemoveObjectFeatures(table_.model(best.model), best_matches);
      ahead_.Clear();  // voted on the scene before this object left it
    }
    if (stats.objects_full) break;
  }
  if (!stats.objects_full) AcceptDeferred(verifier, budget, objects, stats);
  deferred_.clear();  // a full object list drops them unseen
  stats.scene_bases_available = generated;
  if (stats_out) *stats_out = stats;
  return Status::Ok();
}

}  // namespace sh
