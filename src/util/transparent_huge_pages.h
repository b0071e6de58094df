#pragma once
// Whether the kernel gives transparent huge pages to memory that asks for them (mode `always` or
// `madvise` in /sys/kernel/mm/transparent_hugepage/enabled; false when it is `never` or unknown).
namespace edgeslam {

bool kernelOffersTransparentHugePages();

}  // namespace edgeslam
