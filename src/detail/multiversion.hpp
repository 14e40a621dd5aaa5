// KDL_SPACE_MULTIVERSION: a hot function compiled twice, for the x86-64 baseline and for
// x86-64-v3 (AVX2, FMA), the loader picking the one the CPU runs (an ifunc). GCC 11 and later
// (target_clones with "arch=" names) on x86-64 Linux; off under ASan and with other compilers
// (clang's target_clones differs), where the baseline build is used.
#pragma once

#if defined(__x86_64__) && defined(__linux__) && defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 11 && \
    !defined(__SANITIZE_ADDRESS__)
#define KDL_SPACE_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define KDL_SPACE_MULTIVERSION
#endif
