// The supporting plane of a frame estimated from the objects found in it, for installations
// without a table file. Most objects stand on the table: each resting object has a face (three
// or more corners) in the table plane, and two or more resting objects whose faces lie in one
// plane fix it far better than any group of 3-D features can (without a table, 40-50 % of the
// 3-D lines of a recorded scene are wrong stereo pairings, most of them under the table, and
// cast shadows and mirror images add their own planes).
//
// Every face of every accepted object, seen from above (the cameras on the upper side of the
// face's plane, not edge-on), is a candidate plane; the one the most objects rest on wins (an
// object rests on a plane when its lowest corner is within the tolerance of it and at least
// three corners are), ties broken by the smaller distances. It is accepted when at least
// min_objects objects rest on it, and refitted by least squares to their corners in it. Objects
// leaning on others, stacked, or wrong models sunk into the table do not rest on it and do not
// move it. With fewer objects, or none agreeing, the frame has no table (as without the
// estimate).
//
// Pure computation: no heap, bounded by kMaxObjects x kMaxModelFaces candidates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "recog/base/status.hpp"
#include "recog/geometry/rigid_transform.hpp"
#include "recog/hashing/recognizer.hpp"
#include "recog/model/model.hpp"
#include "recog/scene/scene.hpp"

namespace sh {

struct TableEstimateConfig {
  // Estimate the plane when no table is given (PipelineConfig::table.known false).
  bool enabled = true;
  // A corner lies in the plane when within this distance of it. Accepted poses err by a few
  // tenths of a millimetre; real tables are flat to a millimetre.
  float tolerance_mm = 2.0f;
  // Objects that must rest on the plane (the face that proposed it counts).
  uint32_t min_objects = 2;
  // The cameras look at the table from above: its normal within this angle of the direction to
  // the left camera at the proposing face, and the camera at least min_height_mm above it.
  float max_view_angle_deg = 80.0f;
  float min_height_mm = 100.0f;
  // With an accepted plane, search again as with a given table: the features under it and far
  // over it dropped, hypotheses sunk into it rejected; its objects replace the first search's.
  // Off: only the objects found that sink into the plane are removed.
  bool search_again = true;
  // With search_again, the first search (without a table) stops once this many objects are
  // accepted (0: it runs to its end): it only has to find the objects for the plane, and the
  // fruitless tail of the search over the unbounded scene is saved when the scene holds that
  // many. When the estimate is then refused, the search without a table runs on to its end.
  uint32_t first_search_objects = 5;
};

// Why an estimate was not accepted (kAccepted when it was).
enum class TableEstimateOutcome : uint8_t {
  kAccepted = 0,
  kDisabled,       // TableEstimateConfig::enabled false, or a table was given
  kTooFewObjects,  // fewer accepted objects than min_objects
  kNoAgreement,    // no face plane that min_objects objects rest on
};
const char* TableEstimateOutcomeName(TableEstimateOutcome o);

struct TableEstimate {
  TableEstimateOutcome outcome = TableEstimateOutcome::kDisabled;
  bool accepted() const { return outcome == TableEstimateOutcome::kAccepted; }
  // Table frame in the left camera frame: z the plane's normal towards the cameras, origin the
  // resting corners' centre in the plane (x, y arbitrary in the plane). Valid when accepted.
  RigidTransform left_T_table;
  uint32_t objects = 0;  // objects considered
  uint32_t resting = 0;  // objects resting on the plane (its support)
  uint32_t corners = 0;  // their corners in the plane (the least-squares fit's points)
  float rms_mm = 0;      // root mean square distance of those corners from the fitted plane
};

// The plane of the objects' resting faces. `models[i]` is the model of `objects[i]`.
Status CheckTableEstimateConfig(const TableEstimateConfig& config);
void EstimateTableFromObjects(const RecognizedObject* objects, const Model* const* models, size_t n,
                              const TableEstimateConfig& config, TableEstimate* out);

// Objects resting on a table (z up, top at z = 0): the lowest corner within tolerance_mm of the
// top and at least three corners that near it, as the estimate counts its support.
uint32_t CountResting(const RecognizedObject* objects, const Model* const* models, size_t n,
                      const RigidTransform& left_T_table, float tolerance_mm);

// Height of the lowest model corner over the table top (table z axis, left camera frame), mm.
float LowestCornerHeightMm(const Model& model, const RigidTransform& cam_T_model,
                           const RigidTransform& left_T_table);

// Keeps the 3-D features between below_mm under the table top and above_mm over it (the
// working volume over a table, WorkingVolume::OverTable, applied after stereo): points outside
// are dropped, lines clipped to the slab (quality scaled by the share kept) and dropped when
// less than min_length_mm remains. Returns the number of features dropped.
uint32_t KeepOverTable(const RigidTransform& left_T_table, float below_mm, float above_mm,
                       float min_length_mm, Scene* scene);

}  // namespace sh
