#include "intrinsics_report.h"

#include "io/camera_file.h"

namespace edgeslam::cli {

nlohmann::json intrinsicsRefinementJson(const MapIntrinsicsRefinement& refinement) {
  const IntrinsicsRefinementResult& r = refinement.result;
  const CameraIntrinsics& in = r.intrinsics;
  nlohmann::json json = {{"adopted", r.adopted},
                         {"fx", in.fx},
                         {"fy", in.fy},
                         {"k1", in.distortion.k1},
                         {"k2", in.distortion.k2},
                         {"rms_before_px", r.rms_before},
                         {"rms_after_px", r.rms_after},
                         {"iterations", r.iterations},
                         {"keyframes", refinement.keyframes},
                         {"points", refinement.points},
                         {"inliers", r.inliers},
                         {"outliers", r.outliers},
                         {"ms", refinement.solve_ms}};
  if (!r.adopted) {
    json["reason"] = r.reason;
    json["estimate"] = {{"fx", r.estimate.fx},
                        {"fy", r.estimate.fy},
                        {"k1", r.estimate.distortion.k1},
                        {"k2", r.estimate.distortion.k2}};
  }
  return json;
}

std::filesystem::path writeRefinedCamera(const std::filesystem::path& out_dir,
                                         const MapIntrinsicsRefinement& refinement) {
  if (!refinement.result.adopted || out_dir.empty()) return {};
  const std::filesystem::path path = out_dir / "camera_refined.yaml";
  saveCameraFile(path, refinement.result.intrinsics);
  return path;
}

}  // namespace edgeslam::cli
