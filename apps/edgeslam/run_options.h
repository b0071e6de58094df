#pragma once
// Options of `edgeslam run` (and later `client`), parsed from the command line.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "io/frame_range.h"
#include "modes/slam_system.h"
#include "network_security_options.h"

namespace edgeslam::cli {

struct RunOptions {
  std::filesystem::path dataset;
  std::string format = "auto";
  std::string sensor = "auto";  // mono|rgbd|stereo; auto = rgbd when the dataset has depth
  std::string mode = "edge";    // edge|local|offload
  std::string link = "none";
  std::string server_address;      // `client`: the edge server; empty = embedded on loopback
  ClientSecurityOptions security;  // `client`: TLS and token
  std::string maps;                // the embedded edge's map store: "" = default, "none" = none
  std::string map_name;            // the edge map this session writes into; "" = a new one
  bool adapt = true;
  // With --realtime: the client fits its per-frame work to its CPU (adapt/compute_budget.h).
  bool compute_adapt = true;
  bool preload = false;  // decode the frames to play before the run (io/preloaded_dataset.h)
  bool semantic = false;
  std::filesystem::path models_dir;  // segmentation models; "" = the shared models folder
  int segment_input = 256;           // detector input side
  int segment_reduce = 2;            // keyframes are segmented at 1/this of full size
  // Refresh keyframes for segmentation at most / at least this many frames apart (0 = none).
  int segment_refresh = SegmentationRefreshOptions{}.max_frames;
  std::optional<int> segment_refresh_min;  // default: SegmentationRefreshOptions, or the most
  // Lost frames bridged by the motion prediction (TrackerOptions::recover_within_frames).
  std::size_t recover_frames = TrackerOptions{}.recover_within_frames;
  // Lost this long (camera time), a new map is started (TrackerOptions::new_map_after_lost_s;
  // 0 = never). The library's default waits; a run does not stay lost for good.
  double new_map_after_s = 3.0;
  std::size_t max_frames = 0;  // 0 = all
  // `--frames A-B[,C-D...]`: only these frames of the dataset, the ranges one after the other.
  std::optional<std::vector<FrameRange>> frames;
  std::size_t repeat = 1;            // `--repeat N`: the frames played N times into one map
  bool realtime = false;             // feed at the dataset's rate (default: as fast as possible)
  bool fast = false;                 // explicit request for the default
  bool deterministic = false;        // local: lock-step back end, one thread, identical runs
  bool localize_only = false;        // local: localise in the stored map --map, change nothing
  std::string route;                 // with localize_only: follow this route of the map
  double checkpoint_radius_m = 0.5;  // a checkpoint counts reached within this of the truth
  std::filesystem::path out_dir;
  std::optional<int> viewer_port;  // serve the web viewer (0 = any free port)
  std::string viewer_host = "127.0.0.1";
  double viewer_linger_s = 0.0;  // keep serving the final map this long after the run
  std::optional<std::filesystem::path> camera_file;
  // Bag-of-words vocabulary for relocalisation and loop closing; "" = the default file next to the
  // binary (vocab/orb_k10_l5.vocab) when present, "none" = without.
  std::string vocabulary;
  bool loop_closing = true;
  // Edge mode, monocular: the client triangulates new points at its keyframes.
  bool client_triangulation = true;
  // Edge mode: the client holds the features and points of about this many keyframes around its
  // latest one (the edge picks them and evicts the rest); 0 = the whole map.
  int client_map_keyframes = 10;
  // Edge mode: uploads leave out the descriptors of keypoints whose point the edge already has.
  bool omit_known_point_descriptors = true;
  // Tuning; unset values keep the defaults (Table I row 1 for local tracking).
  std::optional<int> features;
  std::optional<int> levels;
  std::optional<int> fmin, fmax;
  std::optional<double> alpha, beta, starving;
  // Local mode: intrinsics the end-of-run self-calibration refines ("off" or a set of focal, k1,
  // k2; optimize/intrinsics_refinement.h); unset = focal,k1.
  std::optional<std::string> refine_intrinsics;
  // Local mapping's new-point search: "bow" or "band"; unset = LocalMapperOptions' default.
  std::optional<std::string> triangulation_search;
};

}  // namespace edgeslam::cli
