// Defines RADIOSITY_THREAD_SANITIZER when the code is compiled with ThreadSanitizer (gcc's
// -fsanitize=thread defines __SANITIZE_THREAD__, clang answers __has_feature). TSan sees only
// instrumented code, and Debian's oneTBB and Embree are not: the parallel loops
// (core/parallel.hpp) and the Embree devices (geometry/ray_scene.hpp) then avoid their worker
// threads, so that what TSan reports are the races of our own code.
#pragma once

#if defined(__SANITIZE_THREAD__)
#define RADIOSITY_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define RADIOSITY_THREAD_SANITIZER 1
#endif
#endif
