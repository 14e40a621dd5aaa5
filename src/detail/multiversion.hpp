// KDL_SPACE_MULTIVERSION: a hot function compiled three times, for the x86-64 baseline, for
// x86-64-v3 (AVX2, FMA) and for x86-64-v4 (AVX-512: the same four-lane vectors, but 32 vector
// registers instead of 16, so that a 6x6 block and its update stay in registers), the loader
// picking the one the CPU runs (an ifunc). On x86-64 Linux with
// GCC 11 or later or clang 14 or later (target_clones with "arch=" names); off under
// AddressSanitizer and elsewhere, where the baseline build is used.
#pragma once

#if defined(__SANITIZE_ADDRESS__)  // GCC's ASan
#define KDL_SPACE_NO_CLONES
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)  // clang's ASan
#define KDL_SPACE_NO_CLONES
#endif
#endif

#if !defined(KDL_SPACE_NO_CLONES) && defined(__x86_64__) && defined(__linux__) && \
    ((defined(__clang__) && __clang_major__ >= 14) || (!defined(__clang__) && defined(__GNUC__) && __GNUC__ >= 11))
#define KDL_SPACE_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3", "arch=x86-64-v4")))
#else
#define KDL_SPACE_MULTIVERSION
#endif
