#include "run_slam_options.h"

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <opencv2/core/utility.hpp>

#include "mapping/local_mapper.h"
#include "optimize/intrinsics_refinement.h"
#include "segmenter_option.h"
#include "vocabulary_option.h"

namespace edgeslam::cli {

SlamOptions slamOptionsForRun(const RunOptions& options, const PinholeCamera& camera,
                              Sensor sensor) {
  const std::string& mode = options.mode;
  SlamOptions slam_options = defaultSlamOptions(camera, sensor);
  if (mode == "edge") {
    slam_options.orb.num_features = std::min(slam_options.orb.num_features, kEdgeClientMaxFeatures);
  }
  if (options.features) slam_options.orb.num_features = *options.features;
  if (options.levels) slam_options.orb.num_levels = *options.levels;
  KeyFrameParameters& kf = slam_options.tracker.keyframes;
  if (options.fmin) kf.fmin = *options.fmin;
  if (options.fmax) kf.fmax = *options.fmax;
  if (options.alpha) kf.alpha = *options.alpha;
  if (options.beta) kf.beta = *options.beta;
  if (options.starving) kf.starving_ratio = *options.starving;
  slam_options.orb.validate();
  slam_options.tracker.vocabulary = loadVocabulary(options.vocabulary);
  slam_options.tracker.recover_within_frames = options.recover_frames;
  slam_options.tracker.new_map_after_lost_s = options.new_map_after_s;
  // The mobile view draws each feature by state; without a viewer nothing is copied.
  slam_options.tracker.report_feature_positions = options.viewer_port.has_value();
  slam_options.backend.vocabulary = slam_options.tracker.vocabulary;
  slam_options.backend.loop_closing = options.loop_closing;
  slam_options.client_triangulation = options.client_triangulation;
  // Paced frames have a deadline and the background has the time between them; unpaced (--fast)
  // tracking always has work, so lowering the mapper would starve it of keyframes.
  slam_options.backend.thread_nice = options.realtime ? kBackgroundNiceWhenPaced : 0;
  // Unpaced, tracking waits for the back end instead of outrunning it (issue 24: KITTI 03 mono
  // drifted to 2.92 m against 0.71 m paced); paced, a late client drops frames instead.
  slam_options.wait_for_backend = !options.realtime;
  if (options.triangulation_search) {
    slam_options.backend.mapper.triangulation_search =
        *parseTriangulationSearch(*options.triangulation_search);
  }
  if (options.deterministic) {
    if (mode != "local") {
      throw CLI::ValidationError("--deterministic",
                                 "applies to --mode local only (edge and offload runs cross "
                                 "processes or threads that are not in lock-step)");
    }
    // The back end runs inside the tracking thread, after each frame; OpenCV's pool stays out of
    // feature extraction so nothing depends on the order threads finish in.
    slam_options.backend.threaded = false;
    cv::setNumThreads(1);
  }
  if (options.localize_only) {
    if (mode == "offload") {
      throw CLI::ValidationError("--localize-only",
                                 "applies to --mode local and edge (an offloading client tracks "
                                 "nothing itself)");
    }
    if (options.map_name.empty()) {
      throw CLI::ValidationError("--localize-only",
                                 "needs --map NAME: the stored map to localise in");
    }
    if (options.semantic) {
      throw CLI::ValidationError("--localize-only",
                                 "and --semantic on: masks come from segmented keyframes, and "
                                 "localisation makes none");
    }
  }
  if (!options.route.empty() && !options.localize_only) {
    throw CLI::ValidationError("--route",
                               "needs --localize-only: a route is followed in a stored map");
  }
  if (options.refine_intrinsics && mode != "local") {
    spdlog::warn("--refine-intrinsics applies to --mode local only; the {} run keeps the camera",
                 mode);
  }
  // The sensor's bounds (defaultSlamOptions) stay; the flag picks what is refined.
  slam_options.intrinsics_refinement =
      parseRefinedIntrinsics(options.refine_intrinsics.value_or("focal,k1"),
                             slam_options.intrinsics_refinement)
          .value();
  slam_options.refine_intrinsics = refinesAnything(slam_options.intrinsics_refinement);
  slam_options.semantic = options.semantic;
  slam_options.keyframe_image_reduce = options.segment_reduce;
  slam_options.segmentation_refresh.max_frames = options.segment_refresh;
  slam_options.segmentation_refresh.min_frames = options.segment_refresh_min.value_or(
      std::min(slam_options.segmentation_refresh.min_frames, options.segment_refresh));
  if (options.semantic && options.server_address.empty()) {
    // The segmenter runs on its own thread beside tracking (and, embedded, beside the edge's
    // mapping) in this process; OpenCV's default pool would spread each inference over every
    // core and stall tracking (RGB-D edge run: end-to-end median 520 ms instead of ~40 ms).
    cv::setNumThreads(1);
    // Loaded here also for the embedded edge: a missing model is reported before any frame is
    // read. A remote edge server checks its own models when the session opens.
    std::shared_ptr<Segmenter> segmenter =
        loadSegmenter(segmenterOptions(options.models_dir, options.segment_input));
    if (mode == "local") slam_options.backend.segmenter = std::move(segmenter);
  }
  return slam_options;
}

}  // namespace edgeslam::cli
