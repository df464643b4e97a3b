#include "detslam/loop/loop_closer.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/features/matcher.h"
#include "detslam/geometry/rigid_ransac.h"
#include "detslam/map/place_candidates.h"
#include "detslam/map/projection_search.h"
#include "detslam/mapping/landmark_fusion.h"
#include "detslam/mapping/map_bundle.h"
#include "detslam/optim/pose_graph.h"
#include "detslam/optim/pose_optimizer.h"
#include "detslam/tracking/keypoint_observation.h"

namespace detslam {

bool LoopClosingOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (min_keyframe_gap < 1) os << "min_keyframe_gap must be >= 1; ";
  if (candidate_window < 0) os << "candidate_window must be >= 0; ";
  if (!(candidate_radius_m >= 0)) os << "candidate_radius_m must be >= 0; ";
  if (consistent_detections < 1) os << "consistent_detections must be >= 1; ";
  if (appearance_candidates < 1) os << "appearance_candidates must be >= 1; ";
  if (confirm_min_matches < 1) os << "confirm_min_matches must be >= 1; ";
  if (max_pending_misses < 1) os << "max_pending_misses must be >= 1; ";
  if (!(revisit_max_correction_m >= 0) || !(revisit_max_correction_deg >= 0))
    os << "revisit_max_correction_m and _deg must be >= 0; ";
  if (max_candidates < 1) os << "max_candidates must be >= 1; ";
  if (min_matches < 3 || min_ransac_inliers < 3)
    os << "min_matches and min_ransac_inliers must be >= 3; ";
  if (!(ransac_inlier_m > 0)) os << "ransac_inlier_m must be positive; ";
  if (min_verified_inliers < 3) os << "min_verified_inliers must be >= 3; ";
  if (merge_weld_keyframes < 0) os << "merge_weld_keyframes must be >= 0; ";
  if (merge_weld_iterations < 1) os << "merge_weld_iterations must be >= 1; ";
  if (error) *error = os.str();
  return os.str().empty();
}

LoopCloser::LoopCloser(const PinholeCamera& camera, LoopClosingOptions options)
    : camera_(camera),
      options_(options),
      rng_(options.seed) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), "invalid LoopClosingOptions: " << error);
}

LoopClosingResult LoopCloser::Process(Map& map, KeyFrameId kf_id) {
  return Process([&map](const MapStep& step) { step(map); }, kf_id, nullptr);
}

LoopClosingResult LoopCloser::Process(const StepRunner& run_step, KeyFrameId kf_id,
                                      const FinishFn& finish, const MovedFn& moved,
                                      const std::function<void()>& before_closing) {
  LoopClosingResult result;
  result.keyframe = kf_id;
  bool searched = false;       // no candidate search this time (disabled, too soon, pending)
  bool by_appearance = false;  // else by position: the first verified candidate closes
  std::vector<KeyFrameId> candidates;
  std::optional<Verified> to_close;
  run_step([&](Map& map) {
    if (!options_.enabled || !map.HasKeyFrame(kf_id)) return;
    if (last_loop_kf_ != kNoKeyFrame && kf_id - last_loop_kf_ < 5) return;
    by_appearance = !map.keyframe(kf_id).features->bow.empty();
    if (!by_appearance) {
      candidates = CandidatesByPosition(map, kf_id);
      searched = true;
      return;
    }
    if (pending_ && ConfirmPending(map, kf_id)) {
      // Confirmed here: no new search (ORB-SLAM3 neither).
      if (pending_->coincidences >= options_.consistent_detections) to_close = *pending_;
      return;
    }
    candidates = CandidatesByAppearance(map, kf_id);
    searched = true;
  });
  std::optional<Verified> best;  // the verified candidate (by appearance: most agreed on)
  if (searched) {
    for (const KeyFrameId candidate : candidates) {
      run_step([&](Map& map) {
        if (!map.HasKeyFrame(kf_id) || !map.HasKeyFrame(candidate)) return;
        Verified loop;
        if (!Verify(map, kf_id, candidate, &loop)) return;
        if (!by_appearance) {
          best = std::move(loop);
          return;
        }
        loop.coincidences = CountCoincidences(map, loop);
        spdlog::debug("  loop candidate {} for keyframe {}: {} keyframes agree", candidate,
                      kf_id, loop.coincidences);
        if (!best || loop.coincidences > best->coincidences) best = std::move(loop);
      });
      if (!by_appearance && best) break;
    }
  }
  // Every change of this object's state is made inside a step (under the caller's lock).
  const bool closing = to_close.has_value() ||
                       (best && (!by_appearance ||
                                 best->coincidences >= options_.consistent_detections));
  if (closing && before_closing) before_closing();
  std::optional<Correction> work;  // a correction with solves left, between steps
  run_step([&](Map& map) {
    // By appearance, the candidate most keyframes agree with replaces a pending loop that fewer
    // agree with.
    if (best && (!by_appearance || best->coincidences >= options_.consistent_detections)) {
      to_close = std::move(best);
    } else if (best && (!pending_ || best->coincidences > pending_->coincidences)) {
      pending_ = std::move(best);
    }
    if (to_close && map.HasKeyFrame(kf_id) && map.HasKeyFrame(to_close->candidate)) {
      Correction c;
      if (Close(map, kf_id, *to_close, &result, &c)) {
        if (moved) {
          moved(map, c.jumped_from);
          c.tracker_moved = true;
        }
        work = std::move(c);
        return;  // `finish` once the correction is applied
      }
    }
    if (finish) finish(map, result);
  });
  if (!work) return result;
  // The solves without the map (ORB-SLAM3 stops local mapping for its MergeLocal and holds the
  // map for the essential graph; here tracking goes on and what it adds meanwhile is taken as it
  // is).
  if (work->weld) {
    BundleOptions bo;
    bo.max_iterations = options_.merge_weld_iterations;
    const BundleSummary weld = SolveBundle(camera_, &work->weld->problem, bo);
    run_step([&](Map& map) { BuildEssentialGraph(map, kf_id, &*work, &weld, &result); });
  }
  const PoseGraphSummary s = SolvePoseGraph(&*work->graph, PoseGraphOptions());
  run_step([&](Map& map) {
    ApplyEssentialGraph(map, kf_id, &*work, s, &result);
    Conclude(&*work, kf_id, &result);
    if (finish) finish(map, result);
  });
  return result;
}

bool LoopCloser::Close(Map& map, KeyFrameId kf_id, const Verified& loop,
                       LoopClosingResult* result, Correction* c) {
  last_loop_kf_ = kf_id;
  pending_.reset();
  result->candidate = loop.candidate;
  result->inliers = loop.inliers;
  result->agreeing = std::max(1, loop.coincidences);
  result->candidate_from_keyframe =
      map.keyframe(loop.candidate).cam_from_world * loop.cam_from_world.Inverse();
  if (map.MapOf(loop.candidate) != map.MapOf(kf_id)) return Merge(map, kf_id, loop, result, c);
  c->loop = loop;
  // A revisit that the map already agrees with (the place seen again with no drift to speak of):
  // the duplicated landmarks are fused, but there is nothing to correct.
  const double moved_m = (loop.cam_from_world.Inverse().translation() -
                          map.keyframe(kf_id).Center()).norm();
  const double turned_deg =
      Eigen::AngleAxisd(loop.correction.rotation()).angle() * 180.0 / M_PI;
  if (moved_m < options_.revisit_max_correction_m &&
      turned_deg < options_.revisit_max_correction_deg) {
    c->correct_poses = false;
    BeginCorrection(map, kf_id, c, result);
    result->revisit = true;
    ++stats_.revisits;
    spdlog::info(
        "place revisited: keyframe {} with keyframe {} ({} inliers, {} keyframes agree, {} "
        "landmarks fused, {:.1f} mm / {:.2f} deg off: no correction)",
        kf_id, loop.candidate, loop.inliers, loop.coincidences, result->fused, moved_m * 1000,
        turned_deg);
    return false;
  }
  BeginCorrection(map, kf_id, c, result);
  return true;
}

bool LoopCloser::Merge(Map& map, KeyFrameId kf_id, Verified loop, LoopClosingResult* result,
                       Correction* c) {
  const int kf_map = map.MapOf(kf_id), candidate_map = map.MapOf(loop.candidate);
  // The map whose root is older keeps its frame (so the map of the first frame never moves);
  // loop.correction is world_candidate_from_world_kf.
  const bool move_current = map.map_roots().at(kf_map) > map.map_roots().at(candidate_map);
  c->merge = true;
  c->merged_from = move_current ? kf_map : candidate_map;
  c->merged_into = move_current ? candidate_map : kf_map;
  c->before_merge =
      move_current ? map.MergeMapInto(c->merged_from, c->merged_into, loop.correction, kf_id,
                                      loop.candidate)
                   : map.MergeMapInto(c->merged_from, c->merged_into, loop.correction.Inverse(),
                                      loop.candidate, kf_id);
  // The verified pose of the keyframe, in the merged map's frame: now close to its own pose.
  if (!move_current) loop.cam_from_world = loop.cam_from_world * loop.correction;
  loop.correction = loop.cam_from_world.Inverse() * map.keyframe(kf_id).cam_from_world;
  c->loop = std::move(loop);
  for (const auto& [id, pose] : c->before_merge) c->moved.insert(id);
  c->jumped_from = c->before_merge;
  BeginCorrection(map, kf_id, c, result);
  for (const auto& [id, pose] : c->before_merge) c->jumped_to[id] = c->old_pose.at(id);
  return true;
}

void LoopCloser::Conclude(Correction* c, KeyFrameId kf_id, LoopClosingResult* result) {
  // The keyframes of the first step's move: the tracker moved with them then (MovedFn), or it
  // moves now from their poses before it.
  for (const auto& [id, pose] : c->jumped_from)
    result->old_poses[id] = c->tracker_moved ? c->jumped_to.at(id) : pose;
  result->closed = true;
  if (!c->merge) {
    ++loops_closed_;
    spdlog::info(
        "loop closed: keyframe {} with keyframe {} ({} inliers, {} keyframes agree, {} landmarks "
        "fused, correction {:.3f} m)",
        kf_id, c->loop.candidate, c->loop.inliers, c->loop.coincidences, result->fused,
        result->correction_m);
    return;
  }
  result->merged = true;
  result->merged_from = c->merged_from;
  result->merged_into = c->merged_into;
  ++maps_merged_;
  spdlog::info(
      "maps merged: map {} into map {} at keyframe {} with keyframe {} ({} inliers, {} keyframes "
      "agree, {} landmarks fused, {} keyframes welded, seam correction {:.3f} m)",
      c->merged_from, c->merged_into, kf_id, c->loop.candidate, c->loop.inliers,
      c->loop.coincidences, result->fused, result->welded_keyframes, result->correction_m);
}

bool LoopCloser::WithinRadius(const Map& map, KeyFrameId kf_id, KeyFrameId other) const {
  return (map.keyframe(other).Center() - map.keyframe(kf_id).Center()).norm() <
         options_.candidate_radius_m;
}

std::vector<KeyFrameId> LoopCloser::CandidatesByPosition(const Map& map, KeyFrameId kf_id) const {
  std::vector<KeyFrameId> out;
  if (!(options_.candidate_radius_m > 0)) return out;  // no vocabulary and no radius: no loops
  const KeyFrame& kf = map.keyframe(kf_id);
  const Eigen::Vector3d center = kf.Center();
  std::vector<std::pair<double, KeyFrameId>> near;
  for (const auto& [id, other] : map.keyframes()) {
    if (id > kf_id - options_.min_keyframe_gap) break;  // ids ascend
    if (kf.covisibility.count(id) || other.map_id != kf.map_id) continue;
    const double d = (other.Center() - center).norm();
    if (d < options_.candidate_radius_m) near.emplace_back(d, id);
  }
  std::sort(near.begin(), near.end());
  spdlog::debug("keyframe {}: {} loop candidates within {} m", kf_id, near.size(),
                options_.candidate_radius_m);
  for (const auto& [d, id] : near) {
    if (out.size() >= static_cast<size_t>(options_.max_candidates)) break;
    out.push_back(id);
  }
  return out;
}

std::vector<KeyFrameId> LoopCloser::CandidatesByAppearance(const Map& map,
                                                           KeyFrameId kf_id) const {
  const int own_map = map.MapOf(kf_id);
  std::set<KeyFrameId> recent;
  for (auto it = map.keyframes().rbegin(); it != map.keyframes().rend(); ++it) {
    if (it->first <= kf_id - options_.min_keyframe_gap) break;
    if (it->second.map_id == own_map) recent.insert(it->first);
  }
  std::vector<PlaceCandidate> found = LoopCandidates(map, kf_id, recent);
  if (options_.candidate_radius_m > 0) {
    found.erase(std::remove_if(found.begin(), found.end(),
                               [&](const PlaceCandidate& c) {
                                 return map.MapOf(c.keyframe) == own_map &&
                                        !WithinRadius(map, kf_id, c.keyframe);
                               }),
                found.end());
  }
  std::vector<KeyFrameId> out;
  for (const PlaceCandidate& c : found) {
    if (out.size() >= static_cast<size_t>(options_.appearance_candidates)) break;
    out.push_back(c.keyframe);
  }
  spdlog::debug("keyframe {}: {} loop candidates by appearance, {} verified", kf_id, found.size(),
                out.size());
  return out;
}

bool LoopCloser::Verify(const Map& map, KeyFrameId kf_id, KeyFrameId candidate_id, Verified* out) {
  const KeyFrame& kf = map.keyframe(kf_id);
  const FrameFeatures& f = *kf.features;
  const KeyFrame& candidate = map.keyframe(candidate_id);
  // Matched against the candidate and its best covisibles (ORB-SLAM3 matches a loop candidate's
  // window the same way): the revisit sees the old place from another viewpoint, so one old
  // keyframe alone often shares too few matches.
  std::vector<const KeyFrame*> window{&candidate};
  for (KeyFrameId n : map.BestCovisibles(candidate_id, options_.candidate_window))
    window.push_back(&map.keyframe(n));
  std::vector<LandmarkId> matched =
      MatchKeyFramesLandmarks(window, f, 0.9, kThHigh, options_.window_search);
  std::vector<Eigen::Vector3d> world, cam;
  std::vector<size_t> kp;
  for (size_t i = 0; i < f.size(); ++i) {
    if (matched[i] == kNoLandmark || f.depth[i] <= 0 || !map.HasLandmark(matched[i])) continue;
    world.push_back(map.landmark(matched[i]).position);
    cam.push_back(camera_.Unproject(f.undist[i], f.depth[i]));
    kp.push_back(i);
  }
  spdlog::debug("loop candidate {} for keyframe {}: {} matches with depth", candidate_id, kf_id,
                kp.size());
  ++stats_.candidates;
  if (static_cast<int>(kp.size()) < options_.min_matches) return false;
  ++stats_.enough_matches;
  RansacOptions ro;
  ro.min_inliers = options_.min_ransac_inliers;
  const RigidRansacResult rr = EstimateRigidRansac(world, cam, options_.ransac_inlier_m, ro, rng_);
  spdlog::debug("  rigid RANSAC: {} inliers", rr.num_inliers);
  if (!rr.success) return false;
  ++stats_.rigid_ransac;

  // Pose-only refinement, then more matches from the candidate's window by projection.
  std::vector<LandmarkId> assoc(f.size(), kNoLandmark);
  for (size_t k = 0; k < kp.size(); ++k) {
    if (rr.inliers[k]) assoc[kp[k]] = matched[kp[k]];
  }
  std::set<LandmarkId> loop_side;
  for (const KeyFrame* n : window) {
    for (LandmarkId lm : n->landmarks) {
      if (lm != kNoLandmark && map.HasLandmark(lm) && loop_side.insert(lm).second)
        out->loop_landmarks.push_back(lm);
    }
  }
  out->candidate = candidate_id;
  if (!Refine(map, kf_id, rr.b_from_a, std::move(assoc), out)) return false;
  ++stats_.verified;
  return true;
}

namespace {

// Pose-only optimisation of `pose` on the associations of `assoc` (per keypoint of `f`); drops the
// outliers from `assoc` and returns the inlier count.
int OptimiseAssociations(const PinholeCamera& camera, const Map& map, const FrameFeatures& f,
                         Rigid3d* pose, std::vector<LandmarkId>* assoc) {
  std::vector<PoseObservation> obs;
  std::vector<size_t> idx;
  for (size_t i = 0; i < f.size(); ++i) {
    if ((*assoc)[i] == kNoLandmark) continue;
    obs.push_back(KeypointObservation(f, i, map.landmark((*assoc)[i]).position, map.scale()));
    idx.push_back(i);
  }
  if (obs.size() < 3) return 0;
  const PoseOptimizerResult r = OptimizePose(camera, *pose, obs, PoseOptimizerOptions());
  *pose = r.cam_from_world;
  for (size_t k = 0; k < obs.size(); ++k) {
    if (!r.inliers[k]) (*assoc)[idx[k]] = kNoLandmark;
  }
  return r.num_inliers;
}

ProjectionSearchOptions LoopProjectionOptions() {
  ProjectionSearchOptions po;
  po.window = 10;
  po.ratio = 0.9;
  return po;
}

}  // namespace

bool LoopCloser::Refine(const Map& map, KeyFrameId kf_id, Rigid3d pose,
                        std::vector<LandmarkId> assoc, Verified* out) const {
  const FrameFeatures& f = *map.keyframe(kf_id).features;
  const bool from_ransac = std::any_of(assoc.begin(), assoc.end(),
                                       [](LandmarkId id) { return id != kNoLandmark; });
  if (from_ransac &&
      OptimiseAssociations(camera_, map, f, &pose, &assoc) < options_.min_ransac_inliers)
    return false;
  std::set<LandmarkId> seen(assoc.begin(), assoc.end());
  std::vector<ProjectionCandidate> candidates;
  for (LandmarkId lm : out->loop_landmarks) {
    if (map.HasLandmark(lm) && seen.insert(lm).second)
      candidates.push_back(CandidateFromLandmark(map.landmark(lm)));
  }
  std::vector<bool> taken(f.size());
  for (size_t i = 0; i < f.size(); ++i) taken[i] = assoc[i] != kNoLandmark;
  const std::vector<int> m = SearchByProjection(camera_, map.scale(), f, pose, candidates, taken,
                                                LoopProjectionOptions());
  for (size_t c = 0; c < candidates.size(); ++c) {
    if (m[c] >= 0) assoc[static_cast<size_t>(m[c])] = candidates[c].landmark;
  }
  const int inliers = OptimiseAssociations(camera_, map, f, &pose, &assoc);
  spdlog::debug("  keyframe {} with loop candidate {}: {} pose-only inliers", kf_id,
                out->candidate, inliers);
  if (inliers < options_.min_verified_inliers) return false;
  out->keyframe = kf_id;
  out->cam_from_world = pose;
  out->correction = pose.Inverse() * map.keyframe(kf_id).cam_from_world;
  out->matched = std::move(assoc);
  out->inliers = inliers;
  return true;
}

int LoopCloser::ProjectionMatches(const Map& map, KeyFrameId kf_id, const Rigid3d& correction,
                                  const std::vector<LandmarkId>& landmarks) const {
  const KeyFrame& kf = map.keyframe(kf_id);
  std::set<LandmarkId> own(kf.landmarks.begin(), kf.landmarks.end());
  std::vector<ProjectionCandidate> candidates;
  for (LandmarkId lm : landmarks) {
    if (map.HasLandmark(lm) && !own.count(lm))
      candidates.push_back(CandidateFromLandmark(map.landmark(lm)));
  }
  const std::vector<bool> taken(kf.size(), false);
  const std::vector<int> m =
      SearchByProjection(camera_, map.scale(), *kf.features, kf.cam_from_world * correction.Inverse(),
                         candidates, taken, LoopProjectionOptions());
  return static_cast<int>(std::count_if(m.begin(), m.end(), [](int i) { return i >= 0; }));
}

int LoopCloser::CountCoincidences(const Map& map, const Verified& loop) const {
  int agree = 1;  // the keyframe that verified it
  for (KeyFrameId n : map.BestCovisibles(loop.keyframe, options_.candidate_window)) {
    if (agree >= options_.consistent_detections) break;
    const int matches = ProjectionMatches(map, n, loop.correction, loop.loop_landmarks);
    spdlog::debug("    covisible keyframe {}: {} projection matches", n, matches);
    if (matches >= options_.confirm_min_matches) ++agree;
  }
  return agree;
}

bool LoopCloser::ConfirmPending(const Map& map, KeyFrameId kf_id) {
  Verified next;
  next.candidate = pending_->candidate;
  next.loop_landmarks = pending_->loop_landmarks;
  const Rigid3d predicted = map.keyframe(kf_id).cam_from_world * pending_->correction.Inverse();
  const bool agrees = Refine(map, kf_id, predicted,
                             std::vector<LandmarkId>(map.keyframe(kf_id).size(), kNoLandmark), &next);
  spdlog::debug("keyframe {}: pending loop with keyframe {} {}", kf_id, pending_->candidate,
                agrees ? "confirmed" : "not confirmed");
  if (!agrees) {
    if (++pending_->misses >= options_.max_pending_misses) {
      pending_.reset();
      ++stats_.pending_dropped;
    }
    return false;
  }
  ++stats_.pending_confirmed;
  next.coincidences = pending_->coincidences + 1;
  pending_ = std::move(next);
  return true;
}

void LoopCloser::BeginCorrection(Map& map, KeyFrameId kf_id, Correction* c,
                                 LoopClosingResult* result) {
  const Verified& loop = c->loop;
  // Poses and positions before the correction.
  for (const auto& [id, k] : map.keyframes()) c->old_pose[id] = k.cam_from_world;
  for (const auto& [id, lm] : map.landmarks()) c->old_position[id] = lm.position;

  // The keyframe's neighbourhood moves rigidly with it: world_new_from_world_old.
  const Rigid3d correction = loop.cam_from_world.Inverse() * c->old_pose.at(kf_id);
  c->group = map.BestCovisibles(kf_id, 1000);
  c->group.push_back(kf_id);
  for (KeyFrameId g : c->group) {
    for (const auto& [n, w] : map.keyframe(g).covisibility) {
      (void)w;
      c->connected_before[g].insert(n);
    }
  }
  c->initial = c->old_pose;
  for (KeyFrameId g : c->group) c->initial[g] = c->old_pose.at(g) * correction.Inverse();

  // Fuse the keyframe's landmarks into the loop landmarks they matched.
  KeyFrame& kf = map.keyframe(kf_id);
  for (size_t i = 0; i < loop.matched.size(); ++i) {
    const LandmarkId into = loop.matched[i];
    if (into == kNoLandmark || !map.HasLandmark(into)) continue;
    const LandmarkId current = kf.landmarks[i];
    if (current == into) continue;
    if (current != kNoLandmark && map.HasLandmark(current)) {
      map.ReplaceLandmark(current, into);
    } else if (!map.landmark(into).observations.count(kf_id)) {
      map.AddObservation(into, kf_id, i);
    } else {
      continue;
    }
    ++result->fused;
  }
  // Then over the whole neighbourhood: the loop side's landmarks projected into every keyframe of
  // the group at its corrected pose (ORB-SLAM's SearchAndFuse); the loop side's landmarks win.
  ProjectionSearchOptions fuse;
  fuse.window = 4.0;
  fuse.ratio = 1.0;
  fuse.max_distance = kThLow;
  for (KeyFrameId g : c->group) {
    result->fused += FuseLandmarksInto(camera_, map, g, loop.loop_landmarks, c->initial.at(g),
                                       fuse, FuseWinner::kSource);
  }
  for (KeyFrameId g : c->group) map.UpdateConnections(g);
  c->moved_from = c->old_pose;
  if (!c->correct_poses) return;
  if (!c->merge) {
    // ORB-SLAM's CorrectLoop: the neighbourhood and the landmarks it made move to the loop's frame
    // now, so that tracking, until the pose graph is applied, sees one copy of the place, not the
    // loop side's landmarks next to the neighbourhood's at their drifted positions.
    const std::set<KeyFrameId> in_group(c->group.begin(), c->group.end());
    for (KeyFrameId g : c->group) {
      c->jumped_from[g] = c->old_pose.at(g);
      map.keyframe(g).cam_from_world = c->moved_from[g] = c->jumped_to[g] = c->initial.at(g);
    }
    for (auto& [id, pos] : c->old_position) {
      if (!map.HasLandmark(id)) continue;  // fused into a loop side's landmark
      const KeyFrameId anchor = LandmarkAnchor(map, id, c->old_pose);
      if (!in_group.count(anchor)) continue;
      Landmark& lm = map.landmark(id);
      pos = lm.position =
          c->initial.at(anchor).Inverse() * (c->old_pose.at(anchor) * lm.position);
      map.UpdateLandmarkGeometry(id);
    }
    BuildEssentialGraph(map, kf_id, c, nullptr, result);
    return;
  }
  if (options_.merge_weld_keyframes <= 0) {
    BuildEssentialGraph(map, kf_id, c, nullptr, result);
    return;
  }

  // A merge's seam (ORB-SLAM3's MergeLocal): the moved map's side (its seam keyframe and best
  // covisibles of its own map; after the fusion they may reach across the seam) is
  // bundle-adjusted against the kept map's side held fixed.
  const size_t side = static_cast<size_t>(options_.merge_weld_keyframes);
  auto side_of = [&](KeyFrameId seam, bool in_moved) {
    std::vector<KeyFrameId> out = {seam};
    for (KeyFrameId k : map.BestCovisibles(seam, 1000)) {
      if (out.size() >= side) break;
      if ((c->moved.count(k) > 0) == in_moved) out.push_back(k);
    }
    return out;
  };
  const bool kf_moved = c->moved.count(kf_id) > 0;
  const std::vector<KeyFrameId> adjust = side_of(kf_moved ? kf_id : loop.candidate, true);
  const std::vector<KeyFrameId> held = side_of(kf_moved ? loop.candidate : kf_id, false);
  MapBundle bundle = BuildWindowBundle(map, adjust, static_cast<int>(side), held);
  if (!bundle.problem.poses.empty() && !bundle.problem.observations.empty()) {
    c->weld = std::move(bundle);
  } else {
    BuildEssentialGraph(map, kf_id, c, nullptr, result);
  }
}

void LoopCloser::BuildEssentialGraph(Map& map, KeyFrameId kf_id, Correction* c,
                                     const BundleSummary* weld, LoopClosingResult* result) {
  const Verified& loop = c->loop;
  // Keyframes and landmarks that tracking made since BeginCorrection (a welded merge, between
  // its steps) are taken where they are; the pose graph moves those keyframes with the
  // neighbours they are tied to, and their landmarks with them.
  std::set<KeyFrameId> made_meanwhile;
  for (const auto& [id, k] : map.keyframes()) {
    if (c->old_pose.emplace(id, k.cam_from_world).second) {
      c->initial[id] = c->moved_from[id] = k.cam_from_world;
      made_meanwhile.insert(id);
    }
  }
  for (const auto& [id, lm] : map.landmarks()) c->old_position.emplace(id, lm.position);

  // A merge's seam: the moved map's side is bundle-adjusted against the kept map now, and the pose
  // graph, with that window and the kept map fixed, bends the rest of the moved map to it. The
  // landmarks then move with their reference keyframes from the poses and positions after the
  // weld (`moved_from`); the edges keep the relative poses from before it.
  std::set<KeyFrameId> welded;
  if (c->weld && weld) {
    if (weld->usable) {
      ApplyMapBundle(*c->weld, *weld, &map);
      for (const BundleProblem::Pose& p : c->weld->problem.poses)
        if (!p.fixed && map.HasKeyFrame(p.id)) welded.insert(p.id);
    } else {
      spdlog::warn("merge: the seam's bundle adjustment failed; the pose graph alone welds it");
    }
  }
  for (KeyFrameId k : welded) c->initial[k] = c->moved_from[k] = map.keyframe(k).cam_from_world;
  if (!welded.empty()) {
    for (auto& [id, pos] : c->old_position)
      if (map.HasLandmark(id)) pos = map.landmark(id).position;
  }
  result->welded_keyframes = static_cast<int>(welded.size());

  // Essential graph: spanning tree, strong covisibility, and the new loop connections.
  const std::set<KeyFrameId> in_group(c->group.begin(), c->group.end());
  PoseGraphProblem problem;
  std::map<KeyFrameId, size_t> node;
  const int own_map = map.MapOf(kf_id);
  for (const auto& [id, k] : map.keyframes()) {
    if (k.map_id != own_map) continue;  // other maps of the atlas are not connected to this one
    node[id] = problem.nodes.size();
    PoseGraphProblem::Node n;
    n.id = id;
    n.cam_from_world = c->initial.at(id);
    n.fixed = map.IsMapRoot(id) || welded.count(id) > 0 ||
              (!welded.empty() && !c->moved.count(id) && !made_meanwhile.count(id));
    problem.nodes.push_back(n);
  }
  std::set<std::pair<KeyFrameId, KeyFrameId>> added;
  auto add_edge = [&](KeyFrameId a, KeyFrameId b, const std::map<KeyFrameId, Rigid3d>& poses) {
    if (a == b || !node.count(a) || !node.count(b)) return;
    if (!added.insert({std::min(a, b), std::max(a, b)}).second) return;
    PoseGraphProblem::Edge e;
    e.from = node.at(a);
    e.to = node.at(b);
    e.from_from_to = poses.at(a) * poses.at(b).Inverse();
    problem.edges.push_back(e);
  };
  // Loop edges first (measured with the corrected group poses).
  add_edge(kf_id, loop.candidate, c->initial);
  for (KeyFrameId g : c->group) {
    if (!map.HasKeyFrame(g)) continue;
    for (const auto& [n, w] : map.keyframe(g).covisibility) {
      (void)w;
      if (!in_group.count(n) && !c->connected_before[g].count(n)) add_edge(g, n, c->initial);
    }
  }
  for (const auto& [id, k] : map.keyframes()) {
    if (k.parent != kNoKeyFrame) add_edge(id, k.parent, c->old_pose);
    for (const auto& [n, w] : k.covisibility) {
      if (w >= options_.essential_min_weight) add_edge(id, n, c->old_pose);
    }
  }
  c->graph = std::move(problem);
}

void LoopCloser::ApplyEssentialGraph(Map& map, KeyFrameId kf_id, Correction* c,
                                     const PoseGraphSummary& s, LoopClosingResult* result) {
  if (!s.usable)
    spdlog::warn("loop closing: pose graph optimisation did not converge; using its last state");
  // Keyframes and landmarks made since the graph was built (tracking went on while it was
  // solved): taken where they are, then the keyframes moved with their parents (the graph's
  // keyframes do not move with theirs) and the landmarks with their reference keyframes.
  std::map<KeyFrameId, Rigid3d> before;  // every keyframe's pose before this step
  for (const auto& [id, k] : map.keyframes()) {
    before[id] = k.cam_from_world;
    if (c->old_pose.emplace(id, k.cam_from_world).second) c->moved_from[id] = k.cam_from_world;
  }
  for (const auto& [id, lm] : map.landmarks()) c->old_position.emplace(id, lm.position);
  std::set<KeyFrameId> solved;
  for (const PoseGraphProblem::Node& n : c->graph->nodes) {
    if (!map.HasKeyFrame(n.id)) continue;
    map.keyframe(n.id).cam_from_world = n.cam_from_world;
    solved.insert(n.id);
  }
  MoveWithParents(solved, before, &map);

  // Every landmark moves with its reference keyframe.
  for (const auto& [id, pos] : c->old_position) {
    if (!map.HasLandmark(id)) continue;
    const KeyFrameId anchor = LandmarkAnchor(map, id, c->moved_from);
    if (anchor == kNoKeyFrame) continue;
    Landmark& lm = map.landmark(id);
    lm.position = map.keyframe(anchor).cam_from_world.Inverse() * (c->moved_from.at(anchor) * pos);
    map.UpdateLandmarkGeometry(id);
  }
  result->correction_m =
      (map.keyframe(kf_id).Center() - c->old_pose.at(kf_id).Inverse().translation()).norm();
  // For the tracker: each keyframe's pose as it was when the tracker last moved with the map
  // (those made meanwhile: as tracking made them); Conclude sets those of the first step's move.
  result->old_poses = std::move(c->old_pose);
}

}  // namespace detslam
