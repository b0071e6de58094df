// Writes the seed corpus of every harness into SEED_DIR/<harness>/: real messages encoded from
// sample records and real frames, and real files from config/ and the shared datasets.
#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "place/vocabulary_training.h"
#include "store/store_fixture.h"
#include "wire/net_test_records.h"
#include "wire/wire_convert.h"

namespace fs = std::filesystem;
using namespace edgeslam;

namespace {

fs::path g_root;

void writeSeed(const std::string& harness, const std::string& name, const std::string& bytes) {
  const fs::path dir = g_root / harness;
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary) << bytes;
}

void writeSeed(const std::string& harness, const std::string& name,
               const google::protobuf::MessageLite& message) {
  writeSeed(harness, name, message.SerializeAsString());
}

std::string bytesOf(const std::vector<std::uint8_t>& v) {
  return {v.begin(), v.end()};
}

// The first `lines` lines of a text file ("" when absent).
std::string head(const fs::path& file, int lines) {
  std::ifstream in(file);
  std::string out;
  std::string line;
  for (int i = 0; i < lines && std::getline(in, line); ++i) out += line + "\n";
  return out;
}

std::vector<std::uint8_t> encode(const std::string& extension, const cv::Mat& image,
                                 std::vector<int> parameters = {}) {
  std::vector<std::uint8_t> bytes;
  cv::imencode(extension, image, bytes, parameters);
  return bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: fuzz_seeds SEED_DIR SHARED_DIR\n";
    return 2;
  }
  g_root = argv[1];
  const fs::path shared = argv[2];
  const fs::path tum = shared / "datasets/tum-fr2desk-20";
  const fs::path kitchen = shared / "datasets/7scenes-redkitchen-1000";
  std::mt19937 rng(1);

  // Real frames (640 x 480, the harnesses' camera), when the shared data is there.
  cv::Mat colour(480, 640, CV_8UC3, cv::Scalar(90, 120, 150));
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(1500));
  try {
    auto reader = openDataset(kitchen);
    const DatasetFrame frame = reader->load(0);
    if (frame.color.size() == colour.size()) colour = frame.color;
    if (!frame.depth.empty()) frame.depth.convertTo(depth, CV_16U, 1000.0);
  } catch (const std::exception& e) {
    std::cerr << "fuzz_seeds: no shared frames (" << e.what() << "), synthetic ones instead\n";
  }
  cv::Mat grey;
  cv::cvtColor(colour, grey, cv::COLOR_BGR2GRAY);
  const auto jpeg = encode(".jpg", grey, {cv::IMWRITE_JPEG_QUALITY, 30});
  const auto colour_jpeg = encode(".jpg", colour, {cv::IMWRITE_JPEG_QUALITY, 30});
  const auto depth_png = encode(".png", depth);
  cv::Mat half;
  cv::resize(colour, half, cv::Size(320, 240), 0, 0, cv::INTER_AREA);
  const auto keyframe_jpeg = encode(".jpg", half, {cv::IMWRITE_JPEG_QUALITY, 30});
  cv::Mat small;
  cv::resize(grey, small, cv::Size(32, 24), 0, 0, cv::INTER_AREA);

  // Wire messages.
  for (int i = 1; i <= 3; ++i) {
    v1::UploadKeyFrameRequest upload;
    upload.mutable_header()->set_protocol_version(kWireProtocolVersion);
    upload.mutable_header()->set_session_id(0x1234);
    KeyFrameUpload record = test::sampleUpload(static_cast<std::uint64_t>(i), 40 * i, 5 * i, rng);
    if (i == 2) record.image_bytes = keyframe_jpeg;
    if (i == 3) record.image_bytes.clear(), record.image_encoding.clear();
    toProto(record, upload.mutable_upload());
    writeSeed("fuzz_keyframe_upload", fmt::format("upload{}", i), upload);

    v1::MapSlice slice;
    toProto(test::sampleSlice(static_cast<std::uint64_t>(i), rng), &slice);
    writeSeed("fuzz_map_slice", fmt::format("slice{}", i), slice);
  }
  v1::OpenSessionRequest open;
  toProto(test::sampleSessionConfig("seed"), &open);
  writeSeed("fuzz_open_session", "open", open);
  SessionConfig mono = test::sampleSessionConfig("mono");
  mono.sensor = Sensor::kMonocular;
  mono.settings.semantic = true;
  toProto(mono, &open);
  writeSeed("fuzz_open_session", "open_mono", open);

  OffloadFrame frame;
  frame.frame_index = 7;
  frame.timestamp = 1305031102.175304;
  frame.image_encoding = "jpeg";
  frame.image_bytes = jpeg;
  v1::OffloadFrameRequest offload;
  toProto(frame, &offload);
  writeSeed("fuzz_offload_frame", "mono", offload);
  frame.image_bytes = colour_jpeg;
  frame.depth_encoding = "png";
  frame.depth_bytes = depth_png;
  toProto(frame, &offload);
  writeSeed("fuzz_offload_frame", "rgbd", offload);

  OffloadResult result;
  result.frame_index = 7;
  result.state = OffloadTrackingState::kOk;
  result.T_cw = test::samplePose(rng);
  result.server_ms = 23.5;
  v1::OffloadFrameReply reply;
  toProto(result, &reply);
  writeSeed("fuzz_offload_reply", "tracked", reply);
  result.state = OffloadTrackingState::kLost;
  result.T_cw.reset();
  toProto(result, &reply);
  writeSeed("fuzz_offload_reply", "lost", reply);

  // Service calls: a selector byte (fuzz_service_calls.cpp), then the request. Session id 0 is the
  // harness's open session.
  const auto call = [](char selector, const google::protobuf::MessageLite& request) {
    return std::string(1, selector) + request.SerializeAsString();
  };
  writeSeed("fuzz_service_calls", "open", call(0, open));
  v1::CloseSessionRequest close;
  close.mutable_header()->set_protocol_version(kWireProtocolVersion);
  writeSeed("fuzz_service_calls", "close", call(1, close));
  {
    v1::UploadKeyFrameRequest upload;
    upload.mutable_header()->set_protocol_version(kWireProtocolVersion);
    toProto(test::sampleUpload(1, 40, 5, rng), upload.mutable_upload());
    writeSeed("fuzz_service_calls", "upload", call(2, upload));
  }
  v1::ProbeRequest probe;
  probe.mutable_header()->set_protocol_version(kWireProtocolVersion);
  probe.set_reply_bytes(512);
  probe.set_payload(std::string(256, 'x'));
  writeSeed("fuzz_service_calls", "probe", call(3, probe));
  offload.mutable_header()->set_protocol_version(kWireProtocolVersion);
  offload.mutable_header()->set_session_id(0);
  writeSeed("fuzz_service_calls", "offload", call(4, offload));
  v1::StreamSlicesRequest stream;
  stream.mutable_header()->set_protocol_version(kWireProtocolVersion);
  stream.set_from_sequence(1);
  writeSeed("fuzz_service_calls", "stream", call(5, stream));
  stream.set_want_full_resync(true);
  writeSeed("fuzz_service_calls", "resync", call(5, stream));

  // Images: the headers and a little of what follows.
  writeSeed("fuzz_image_header", "grey.jpg", bytesOf(jpeg).substr(0, 4096));
  writeSeed("fuzz_image_header", "colour.jpg", bytesOf(colour_jpeg).substr(0, 4096));
  writeSeed("fuzz_image_header", "depth.png", bytesOf(depth_png).substr(0, 4096));
  writeSeed("fuzz_image_header", "small.png", bytesOf(encode(".png", small)));

  // Files.
  for (const auto& entry :
       fs::directory_iterator(fs::path(EDGESLAM_SOURCE_DIR) / "config/cameras")) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::ostringstream content;
    content << in.rdbuf();
    writeSeed("fuzz_camera_yaml", entry.path().filename().string(), content.str());
  }
  writeSeed("fuzz_trajectory_files", "tum",
            std::string(1, '\0') + head(tum / "groundtruth.txt", 30));
  writeSeed("fuzz_trajectory_files", "kitti_poses",
            std::string(1, '\1') + head(shared / "datasets/kitti07-160/poses.txt", 20));
  writeSeed("fuzz_trajectory_files", "kitti_times",
            std::string(1, '\2') + head(shared / "datasets/kitti07-160/times.txt", 20));
  writeSeed("fuzz_dataset_index", "rgb.txt", head(tum / "rgb.txt", 20));

  // A small vocabulary trained on random descriptors, in the file format `vocab train` writes.
  std::vector<cv::Mat> descriptors;
  for (int image = 0; image < 4; ++image) {
    cv::Mat d(60, 32, CV_8UC1);
    cv::randu(d, 0, 256);
    descriptors.push_back(d);
  }
  VocabularyTrainingOptions options;
  options.branching = 3;
  options.levels = 2;
  options.threads = 1;
  const fs::path vocab = g_root / "words.vocab";
  trainVocabulary(descriptors, options).save(vocab);
  std::ifstream in(vocab, std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  writeSeed("fuzz_vocabulary_file", "k3l2.vocab", content.str());
  fs::remove(vocab);

  // A small store as a server leaves it: one map of three keyframes, written by the store writer.
  const fs::path store_dir = g_root / "store";
  fs::remove_all(store_dir);
  {
    test::SmallMap small(40);
    std::shared_ptr<MapStore> store = openMapStore(store_dir, MapStoreAccess::kServe);
    const StoreSessionId session = store->beginSession("kitchen", small.info());
    MapStoreWriter writer(store, session, small.map, std::make_shared<MapStoreWriteStats>());
    {
      MutexLock lock(small.map.updateMutex());
      writer.onMapChanged(small.map.takeChanges());
    }
    writer.stop();
  }
  std::ifstream store_file(store_dir / "maps.sqlite", std::ios::binary);
  std::ostringstream store_bytes;
  store_bytes << store_file.rdbuf();
  writeSeed("fuzz_map_store", "small.sqlite", store_bytes.str());
  fs::remove_all(store_dir);
  return 0;
}
