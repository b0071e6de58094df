#include "modes/offload_slam.h"

#include <opencv2/imgcodecs.hpp>

namespace edgeslam {

OffloadSlam::OffloadSlam(Sensor sensor, std::unique_ptr<EdgeClient> client, OffloadOptions options)
    : sensor_(sensor),
      client_(std::move(client)),
      options_(options),
      encode_params_{cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality} {}

OffloadSlam::~OffloadSlam() {
  client_->close();
}

TrackResult OffloadSlam::process(std::size_t frame_index, double timestamp, const cv::Mat& gray,
                                 const cv::Mat& depth, const cv::Mat& /*color*/) {
  OffloadFrame frame;
  frame.frame_index = frame_index;
  frame.timestamp = timestamp;
  frame.image_encoding = "jpeg";
  cv::imencode(".jpg", gray, frame.image_bytes, encode_params_);
  if (sensor_ != Sensor::kMonocular && !depth.empty()) {
    cv::Mat millimetres;
    depth.convertTo(millimetres, CV_16U, 1000.0);
    frame.depth_encoding = "png";
    cv::imencode(".png", millimetres, frame.depth_bytes);
  }
  TrackResult result;
  const std::optional<OffloadResult> answer = client_->offloadFrame(frame);
  if (!answer) {
    result.state = TrackingState::kLost;  // no answer in time: the client has no pose
    return result;
  }
  server_ms_.add(answer->server_ms);
  backend_waits_.add(answer->backend_wait_ms);
  switch (answer->state) {
    case OffloadTrackingState::kOk:
      result.state = TrackingState::kOk;
      break;
    case OffloadTrackingState::kLost:
      result.state = TrackingState::kLost;
      break;
    default:
      result.state = TrackingState::kNotInitialized;
  }
  result.T_cw = answer->T_cw;
  if (result.state == TrackingState::kOk && result.T_cw) {
    poses_.push_back({timestamp, result.T_cw->inverse()});
  }
  return result;
}

LinkTraffic OffloadSlam::linkTraffic() const {
  const EdgeClientCounters c = client_->counters();
  return {c.uplink_bytes, c.downlink_bytes};
}

SlamCounters OffloadSlam::counters() const {
  const EdgeClientCounters c = client_->counters();
  SlamCounters out;
  out.exchange.uplink_bytes = c.uplink_bytes;
  out.exchange.downlink_bytes = c.downlink_bytes;
  out.exchange.reconnects = c.reconnects;
  out.exchange.edge_frame_ms = server_ms_.summary();
  out.backend = backend_waits_.pacing();
  return out;
}

}  // namespace edgeslam
