#pragma once
// Internal helpers shared by the dataset readers: text tables, image decoding and checks, camera
// resolution (dataset camera vs --camera override), a base class holding the per-frame tables.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.h"

namespace edgeslam::detail {

// One non-blank, non-comment line of a text table, split on whitespace and commas.
struct TableRow {
  int line = 0;  // 1-based
  std::vector<std::string> fields;
};

// Reads a '#'-commented text table; each row must have at least `min_fields` fields.
std::vector<TableRow> readTable(const std::filesystem::path& path, std::size_t min_fields);
double parseNumber(const std::string& token, const std::filesystem::path& path, int line);

// Decodes an image (cv::IMREAD_UNCHANGED) or throws naming the file.
cv::Mat readImage(const std::filesystem::path& path);
// Fills frame.gray (always) and frame.color (when `image` has colour) from a decoded image.
void setImages(const cv::Mat& image, const std::filesystem::path& path, DatasetFrame& frame);
// 16-bit depth image -> CV_32FC1 metres; 0 and `invalid_value` (when given) become 0.
cv::Mat depthToMetres(const cv::Mat& raw, double depth_factor, const std::filesystem::path& path,
                      std::optional<std::uint16_t> invalid_value = std::nullopt);
// Throws when `image` is not `expected` in size, naming the file and both sizes.
void checkImageSize(const cv::Mat& image, cv::Size expected, const std::filesystem::path& path,
                    const char* what);
cv::Size imageSize(const PinholeCamera& camera);

// The camera a reader uses: the override when given (checked against the first image, keeping the
// dataset's depth_factor / baseline / fps where the override leaves them 0), else `native`.
// Throws `missing_camera_message` when neither exists.
PinholeCamera resolveCamera(const std::optional<CameraIntrinsics>& native,
                            const DatasetOptions& options, cv::Size first_image_size,
                            const std::filesystem::path& first_image,
                            const std::string& missing_camera_message);

// Frame rate from the median frame interval; 0 when fewer than two timestamps.
double fpsFromTimestamps(const std::vector<double>& timestamps);

// Last component of a folder path, also for "dir/" and "." forms.
std::string folderName(const std::filesystem::path& folder);

bool isImageFile(const std::filesystem::path& path);
// Image files directly inside `folder`, sorted naturally (frame2 before frame10).
std::vector<std::filesystem::path> listImages(const std::filesystem::path& folder);
bool naturalLess(const std::string& a, const std::string& b);
// Frame number of a 7-Scenes colour image name (frame-000123.color.png|jpg -> 123).
std::optional<long> sevenScenesFrameNumber(const std::string& file_name);

// Fills frame.gray, and frame.color when `color` is set and the image has colour (as setImages).
// Grey is always converted from the decoded colour, never decoded as the JPEG's own luma: the two
// differ by a grey level here and there, and tracking must see the same frames whatever else a run
// asks for (behind lte-congested, that difference decided whether a monocular client relocalised).
// Throws DatasetError naming the file.
void readFrameImage(const std::filesystem::path& path, bool color, DatasetFrame& frame);

// Holds what every reader knows before loading images.
class TabulatedReader : public DatasetReader {
 public:
  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return camera_; }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return ground_truth_; }

 protected:
  // Starts a frame: checks the index, fills index, timestamp, name and ground truth.
  DatasetFrame beginFrame(std::size_t index, std::string name) const;
  // Sets frame_count, has_ground_truth; call once the tables are filled.
  void finishTables();

  DatasetInfo info_;
  PinholeCamera camera_;
  std::vector<double> timestamps_;
  std::vector<std::optional<SE3d>> ground_truth_;
};

}  // namespace edgeslam::detail
