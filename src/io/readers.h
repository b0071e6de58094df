#pragma once
// Internal: one constructor per dataset format (each in its own file); openDataset dispatches.
#include <filesystem>
#include <memory>

#include "io/dataset.h"

namespace edgeslam::detail {

std::unique_ptr<DatasetReader> openTumDataset(const std::filesystem::path& folder,
                                              const DatasetOptions& options);
std::unique_ptr<DatasetReader> openKittiDataset(const std::filesystem::path& folder,
                                                const DatasetOptions& options);
std::unique_ptr<DatasetReader> openEurocDataset(const std::filesystem::path& folder,
                                                const DatasetOptions& options);
std::unique_ptr<DatasetReader> openSevenScenesDataset(const std::filesystem::path& folder,
                                                      const DatasetOptions& options);
std::unique_ptr<DatasetReader> openImageFolderDataset(const std::filesystem::path& folder,
                                                      const DatasetOptions& options);
std::unique_ptr<DatasetReader> openVideoDataset(const std::filesystem::path& file,
                                                const DatasetOptions& options);

}  // namespace edgeslam::detail
