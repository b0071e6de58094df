#pragma once
// Plain types of the wire that are not map records: what a session is opened with, and the
// whole-frame offload of the Mask-SLAM baseline mode.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/se3.h"
#include "map/sensor.h"

namespace edgeslam {

// The protocol version this build speaks (RequestHeader.protocol_version).
constexpr std::uint32_t kWireProtocolVersion = 1;

struct SessionSettings {
  int features = 1000;
  int pyramid_levels = 8;
  double scale_factor = 1.2;
  bool semantic = true;
  // Keyframes the client holds with features and points, around its latest one; 0 = unbounded.
  int client_map_keyframes = 0;
  // Localise in the stored map named by SessionConfig::map_name, changing nothing in it.
  bool localize_only = false;
  // Offload mode: recorded frames fed back to back; the edge paces its tracking by its back end.
  bool frames_back_to_back = false;
};

// What a client opens a session with; id_origin and session_id are filled in by the server.
struct SessionConfig {
  std::string client_name;
  std::string map_name;  // the edge map to write into; "" = a new one
  PinholeCamera camera;
  Sensor sensor = Sensor::kMonocular;
  SessionSettings settings;
  std::uint64_t session_id = 0;
  std::uint8_t id_origin = 0;  // top byte of every id the client makes
};

// One whole frame sent to the edge (offload mode).
struct OffloadFrame {
  std::uint64_t frame_index = 0;
  double timestamp = 0.0;
  std::string image_encoding;  // "jpeg" or "png"
  std::vector<std::uint8_t> image_bytes;
  std::string depth_encoding;  // "" (none) or "png" (16-bit)
  std::vector<std::uint8_t> depth_bytes;
};

enum class OffloadTrackingState { kNotInitialized, kOk, kLost };

struct OffloadResult {
  std::uint64_t frame_index = 0;
  OffloadTrackingState state = OffloadTrackingState::kNotInitialized;
  std::optional<SE3d> T_cw;      // camera-from-world when tracked
  double server_ms = 0.0;        // time the edge spent on the frame
  double backend_wait_ms = 0.0;  // of it, its tracking's wait for its back end (paced offline)
};

}  // namespace edgeslam
