#pragma once
// Clang's thread-safety attributes as macros (empty on other compilers). The clang build compiles
// with -Wthread-safety, so a field marked GUARDED_BY(m) read or written without m held, or a
// function marked REQUIRES(m) called without it, is a compile error there.
#if defined(__clang__)
#define EDGESLAM_THREAD_ATTRIBUTE(x) __attribute__((x))
#else
#define EDGESLAM_THREAD_ATTRIBUTE(x)
#endif

#define CAPABILITY(name) EDGESLAM_THREAD_ATTRIBUTE(capability(name))
#define SCOPED_CAPABILITY EDGESLAM_THREAD_ATTRIBUTE(scoped_lockable)
#define GUARDED_BY(m) EDGESLAM_THREAD_ATTRIBUTE(guarded_by(m))
#define PT_GUARDED_BY(m) EDGESLAM_THREAD_ATTRIBUTE(pt_guarded_by(m))
#define REQUIRES(...) EDGESLAM_THREAD_ATTRIBUTE(requires_capability(__VA_ARGS__))
#define REQUIRES_SHARED(...) EDGESLAM_THREAD_ATTRIBUTE(requires_shared_capability(__VA_ARGS__))
#define ACQUIRE(...) EDGESLAM_THREAD_ATTRIBUTE(acquire_capability(__VA_ARGS__))
#define ACQUIRE_SHARED(...) EDGESLAM_THREAD_ATTRIBUTE(acquire_shared_capability(__VA_ARGS__))
#define RELEASE(...) EDGESLAM_THREAD_ATTRIBUTE(release_capability(__VA_ARGS__))
#define RELEASE_SHARED(...) EDGESLAM_THREAD_ATTRIBUTE(release_shared_capability(__VA_ARGS__))
#define RELEASE_GENERIC(...) EDGESLAM_THREAD_ATTRIBUTE(release_generic_capability(__VA_ARGS__))
#define TRY_ACQUIRE(...) EDGESLAM_THREAD_ATTRIBUTE(try_acquire_capability(__VA_ARGS__))
#define EXCLUDES(...) EDGESLAM_THREAD_ATTRIBUTE(locks_excluded(__VA_ARGS__))
#define ASSERT_CAPABILITY(x) EDGESLAM_THREAD_ATTRIBUTE(assert_capability(x))
#define RETURN_CAPABILITY(x) EDGESLAM_THREAD_ATTRIBUTE(lock_returned(x))
#define NO_THREAD_SAFETY_ANALYSIS EDGESLAM_THREAD_ATTRIBUTE(no_thread_safety_analysis)
