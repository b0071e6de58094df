#pragma once
// The heap on transparent huge pages (glibc's `glibc.malloc.hugetlb=1` tunable). A map of a
// thousand keyframes is ~450 MB of small objects; on 4 KiB pages loading it spent about a quarter
// of its time in page faults (1045 keyframes: 1018 -> 681 ms median with huge pages; docs/
// map_store.md, "The heap on huge pages"). glibc reads its tunables only when a process starts, so
// the binary starts itself again once with the tunable set (same pid, same arguments), for the
// commands that hold maps (server, run, client, map; a restart costs a second start). Nothing
// happens when the tunable is already set, when EDGESLAM_HUGE_PAGES=0, when the kernel has
// transparent huge pages off, under a sanitizer (its own allocator), or when the restart fails.
namespace edgeslam::cli {

void restartWithHugePageHeap(char** argv);

}  // namespace edgeslam::cli
