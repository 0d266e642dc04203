// Offline preprocessing of the 2-D geometric hashing (thesis 6.3, 6.4.1): aspect models over a
// tessellated viewing sphere, refined where test views half way between the stored views do not
// find their model, every basis of every aspect with the other corners and segments expressed
// in it, binned into the two hash arrays and serialised as an aspect table (aspect_format.hpp).
//
// Host only (the `stereohash tables build --hash-2d` command and the build step that links the
// default aspect table into the firmware); it allocates freely.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "recog/base/status.hpp"
#include "recog/model/model.hpp"
#include "recog/mono/aspect_voter.hpp"
#include "tables/aspect_format.hpp"

namespace sh {

struct AspectBuildOptions {
  AspectBasisKind kind = AspectBasisKind::kSimilarity;
  // Thesis 6.4.1: initial grid 15 degrees apart, up to 3 recursive refinements; a test view
  // passes when half of its bases give a correct aspect model at least 20 % of the maximum
  // vote, with vote widths of 5 px for corners and 3 px for lines. Here the initial grid is 10
  // degrees apart: with its 635 aspects the reference models' tables hold about as many
  // entries as the thesis's (54,000 / 86,000 against 60,720 / 100,182) and no test view fails;
  // a 15-degree grid refined with stricter tests needs more aspects for the same recognition
  // (docs/monocular.md).
  float initial_spacing_deg = 10.0f;
  int max_levels = 3;
  bool refine = true;
  float distance_factor = 10.0f;
  float min_corner_angle_deg = 20.0f;
  float min_segment_fraction = 0.15f;
  // Basis sides shorter than this fraction of the aspect's radius are not used (the thesis's
  // 40 px lower limit on basis lengths, for objects of about 150 px).
  float min_basis_fraction = 0.5f;
  // Only bases whose corners are joined by visible edges (Gavrila & Groen; thesis 6.4.1 notes
  // it keeps the tables small): recognition tries such scene bases. false: every corner pair
  // or triple, as the thesis's tables (60,720 / 100,182 entries).
  bool edge_bases_only = true;
  float test_sigma_point_px = 5.0f;
  float test_sigma_line_px = 3.0f;
  float test_scale_px = 75.0f;  // test views scaled to this radius: an object at about 450 mm
  float test_vote_fraction = 0.2f;
  float test_pass_fraction = 0.5f;
  // Features farther than this from a basis's origin, in either hash coordinate (basis
  // lengths), are not stored for it.
  float max_hash_coordinate = 4.0f;
  float point_bin = 0.1f;  // hash units
  float line_bin = 0.2f;   // segment centres, hash units
  int line_angle_slices = 18;
  int size_slices = 6;
};

struct AspectModelReport {
  std::string model;
  uint32_t aspects = 0;
  uint32_t aspects_per_level[8] = {};
  uint32_t test_views = 0;
  uint32_t failed_test_views = 0;  // failures that led to a refinement (or at the last level)
  uint32_t bases = 0;
  uint32_t point_entries = 0;
  uint32_t line_entries = 0;
};

struct AspectBuildReport {
  std::vector<AspectModelReport> per_model;
  uint32_t aspects = 0;
  uint32_t bases = 0;
  uint32_t point_entries = 0;
  uint32_t line_entries = 0;
  uint32_t max_point_bin_entries = 0;
  uint32_t max_line_bin_entries = 0;
};

// Builds the aspect table of `models`. Models get their symmetry group filled in on the way.
Result<std::vector<uint8_t>> BuildAspectBlob(std::vector<Model> models,
                                             const AspectBuildOptions& options,
                                             AspectBuildReport* report = nullptr);

}  // namespace sh
