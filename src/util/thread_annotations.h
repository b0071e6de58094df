#pragma once
// Clang's thread-safety attributes as macros (empty on other compilers). The clang build compiles
// with -Wthread-safety, so a field marked GUARDED_BY(m) read or written without m held, or a
// function marked REQUIRES(m) called without it, is a compile error there.
// gRPC's headers define some of the same names with the same meaning: ours replace them.
#if defined(__clang__)
#define EDGESLAM_THREAD_ATTRIBUTE(x) __attribute__((x))
#else
#define EDGESLAM_THREAD_ATTRIBUTE(x)
#endif

#undef CAPABILITY
#define CAPABILITY(name) EDGESLAM_THREAD_ATTRIBUTE(capability(name))
#undef SCOPED_CAPABILITY
#define SCOPED_CAPABILITY EDGESLAM_THREAD_ATTRIBUTE(scoped_lockable)
#undef GUARDED_BY
#define GUARDED_BY(m) EDGESLAM_THREAD_ATTRIBUTE(guarded_by(m))
#undef PT_GUARDED_BY
#define PT_GUARDED_BY(m) EDGESLAM_THREAD_ATTRIBUTE(pt_guarded_by(m))
#undef REQUIRES
#define REQUIRES(...) EDGESLAM_THREAD_ATTRIBUTE(requires_capability(__VA_ARGS__))
#undef REQUIRES_SHARED
#define REQUIRES_SHARED(...) EDGESLAM_THREAD_ATTRIBUTE(requires_shared_capability(__VA_ARGS__))
#undef ACQUIRE
#define ACQUIRE(...) EDGESLAM_THREAD_ATTRIBUTE(acquire_capability(__VA_ARGS__))
#undef ACQUIRE_SHARED
#define ACQUIRE_SHARED(...) EDGESLAM_THREAD_ATTRIBUTE(acquire_shared_capability(__VA_ARGS__))
#undef RELEASE
#define RELEASE(...) EDGESLAM_THREAD_ATTRIBUTE(release_capability(__VA_ARGS__))
#undef RELEASE_SHARED
#define RELEASE_SHARED(...) EDGESLAM_THREAD_ATTRIBUTE(release_shared_capability(__VA_ARGS__))
#undef RELEASE_GENERIC
#define RELEASE_GENERIC(...) EDGESLAM_THREAD_ATTRIBUTE(release_generic_capability(__VA_ARGS__))
#undef TRY_ACQUIRE
#define TRY_ACQUIRE(...) EDGESLAM_THREAD_ATTRIBUTE(try_acquire_capability(__VA_ARGS__))
#undef EXCLUDES
#define EXCLUDES(...) EDGESLAM_THREAD_ATTRIBUTE(locks_excluded(__VA_ARGS__))
#undef ASSERT_CAPABILITY
#define ASSERT_CAPABILITY(x) EDGESLAM_THREAD_ATTRIBUTE(assert_capability(x))
#undef RETURN_CAPABILITY
#define RETURN_CAPABILITY(x) EDGESLAM_THREAD_ATTRIBUTE(lock_returned(x))
#undef NO_THREAD_SAFETY_ANALYSIS
#define NO_THREAD_SAFETY_ANALYSIS EDGESLAM_THREAD_ATTRIBUTE(no_thread_safety_analysis)
