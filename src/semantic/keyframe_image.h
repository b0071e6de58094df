#pragma once
// The keyframe image that goes up with an upload for the edge to segment: reduced and JPEG-coded
// on the link's thread (the client's tracking thread only hands the image over).
#include "map/map_records.h"

namespace edgeslam {

struct KeyFrameImageOptions {
  int downscale = 2;  // each side divided by this (area averaging)
  int jpeg_quality = 60;
};

// Moves upload.raw_image (8-bit grey or BGR) into image_bytes / image_encoding; nothing to do
// without a raw image. Throws std::invalid_argument for another image type or bad options.
void compressKeyFrameImage(KeyFrameUpload& upload, const KeyFrameImageOptions& options = {});

}  // namespace edgeslam
