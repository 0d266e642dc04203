// Whether an object found by one path is an object another path found already: the centroid of
// its corners, in the other object's model frame, inside the box of the other's corners. A
// polyhedron read from a printed carton's box edges, or from a colour part's outline (a bracket's
// straight edges read as a wedge, a red cube read as the polyhedral cube), lies inside that object;
// two real parts cannot, as solids do not interpenetrate. The one-camera search uses the same
// test between its own objects (a wrong model fitted beside a real object holds its centre).
#pragma once

#include <cstddef>

#include "recog/geometry/rigid_transform.hpp"
#include "recog/model/model.hpp"
#include "recog/verify/view_camera.hpp"

namespace sh {

// `cam_T_model` and the others' poses in one camera frame. False for an empty model.
bool CentreInside(const Model& model, const RigidTransform& cam_T_model, const PosedModel& other);

// True if either object's centre lies inside the other (CentreInside both ways): the two claim
// one place.
bool Interpenetrate(const PosedModel& a, const PosedModel& b);

// Index of the first of `others` (n of them) that CentreInside() holds for, or -1.
int CentreInsideAny(const Model& model, const RigidTransform& cam_T_model, const PosedModel* others,
                    size_t n);

}  // namespace sh
