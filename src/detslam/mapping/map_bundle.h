// Bundle adjustment over part of the map: builds the solver's plain problem from keyframes and
// their landmarks, and applies a solved problem back (local BA of the local mapper, global BA
// after loop closing).
#pragma once

#include <atomic>
#include <functional>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/map/map.h"
#include "detslam/map/map_store.h"
#include "detslam/optim/bundle_adjustment.h"

namespace detslam {

struct MapBundle {
  BundleProblem problem;
  std::vector<std::pair<LandmarkId, KeyFrameId>> observation_ref;  // per problem observation
};

// Poses: `free` keyframes (optimised, except the map's first keyframe, which anchors the gauge)
// then `fixed` ones; points: every landmark seen by a free keyframe, with its observations in
// any keyframe of the problem. Returns an empty problem when nothing would be fixed (no gauge).
MapBundle BuildMapBundle(const Map& map, const std::vector<KeyFrameId>& free,
                         const std::vector<KeyFrameId>& fixed);

// A local window: `window` optimised (except a map root), `held` (outside it) held fixed, and the
// other keyframes that observe the window's landmarks most (up to `max_fixed`, ties by id) held
// fixed too (ORB-SLAM's local bundle adjustment; a merge's welding window against the kept map's
// side). Empty when nothing would be fixed (no gauge).
MapBundle BuildWindowBundle(const Map& map, const std::vector<KeyFrameId>& window, int max_fixed,
                            const std::vector<KeyFrameId>& held = {});

// Writes a solved bundle back: erases the observations the solver marked as outliers, sets the
// free poses and the points (updating their geometry). Keyframes or landmarks removed meanwhile
// are skipped. Returns the number of observations erased.
int ApplyMapBundle(const MapBundle& bundle, const BundleSummary& summary, Map* map);

// Keyframes not in `solved` move with their spanning-tree parent, every map's tree from its root
// down (child_from_parent kept as in `before`: every keyframe's pose before the solved ones were
// set), e.g. those created while a solution was computed without the map lock.
void MoveWithParents(const std::set<KeyFrameId>& solved,
                     const std::map<KeyFrameId, Rigid3d>& before, Map* map);

// The keyframe a landmark moves with in a correction: its reference keyframe, else (erased, or
// without a pose in `poses`) its first observer; kNoKeyFrame when that is not in the map or has no
// pose in `poses` either.
KeyFrameId LandmarkAnchor(const Map& map, LandmarkId id, const std::map<KeyFrameId, Rigid3d>& poses);

// After ApplyMapBundle of a bundle built earlier: keyframes the bundle did not hold (created while
// it was solved) move with their spanning-tree parent, landmarks it did not hold with their
// reference keyframe (else their first observer). `before`: every keyframe's pose before
// ApplyMapBundle.
void PropagateBundleCorrection(const MapBundle& bundle, const std::map<KeyFrameId, Rigid3d>& before,
                               Map* map);

// Bundle adjustment of the whole map (first keyframe fixed) by the snapshot-solve-apply pattern
// (MapStore::ComputeOutsideLock): the map as it is now is solved without the lock, so tracking
// goes on meanwhile; keyframes created meanwhile follow their spanning-tree parent's correction
// (ORB-SLAM's propagation after its global BA thread) and landmarks created meanwhile their
// reference keyframe's. `applied` (may be empty) runs under the same lock right after the update,
// with every keyframe's pose before it (e.g. to move the tracker's last frame). `still_valid` (may
// be empty), checked under the lock before the update, can discard a solution that the map has
// outgrown (e.g. a newer loop correction). When *abort_flag (may be null) becomes true the solver
// stops after its current iteration (ORB-SLAM3 stops its global BA when a new loop is found).
// Returns the solver summary (not usable, or discarded: nothing changed).
using MapUpdatedFn = std::function<void(Map&, const std::map<KeyFrameId, Rigid3d>& old_poses)>;
BundleSummary GlobalBundleAdjustment(const PinholeCamera& camera, int iterations, MapStore* store,
                                     const MapUpdatedFn& applied = nullptr,
                                     const std::function<bool(const Map&)>& still_valid = nullptr,
                                     const std::atomic<bool>* abort_flag = nullptr);

}  // namespace detslam
