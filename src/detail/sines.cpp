#include "detail/sines.hpp"

#include <cmath>

#if defined(KDL_SPACE_HAVE_MVEC) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define KDL_SPACE_MVEC_CALLS 1

// libmvec's entry points, by the x86-64 vector function ABI: 'b' two lanes in xmm registers
// (SSE2, every x86-64), 'd' four lanes in ymm registers (AVX2). Each picks the best code for the
// CPU itself.
extern "C" {
__m128d _ZGVbN2v_sin(__m128d);
__m128d _ZGVbN2v_cos(__m128d);
__attribute__((target("avx2,fma"))) __m256d _ZGVdN4v_sin(__m256d);
__attribute__((target("avx2,fma"))) __m256d _ZGVdN4v_cos(__m256d);
}
#endif

namespace kdl_space::detail {

#ifdef KDL_SPACE_MVEC_CALLS
namespace {
__attribute__((target("avx2,fma"))) std::size_t fours(const double* t, double* s, double* c, std::size_t n) {
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const __m256d x = _mm256_loadu_pd(t + i);
    _mm256_storeu_pd(s + i, _ZGVdN4v_sin(x));
    _mm256_storeu_pd(c + i, _ZGVdN4v_cos(x));
  }
  return i;
}

std::size_t twos(const double* t, double* s, double* c, std::size_t n) {
  std::size_t i = 0;
  for (; i + 2 <= n; i += 2) {
    const __m128d x = _mm_loadu_pd(t + i);
    _mm_storeu_pd(s + i, _ZGVbN2v_sin(x));
    _mm_storeu_pd(c + i, _ZGVbN2v_cos(x));
  }
  return i;
}

const bool avx2 = (__builtin_cpu_init(), __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"));
}  // namespace
#endif

void sinesAndCosines(const double* t, double* s, double* c, std::size_t n) {
  std::size_t i = 0;
#ifdef KDL_SPACE_MVEC_CALLS
  i = avx2 ? fours(t, s, c, n) : twos(t, s, c, n);
#endif
  for (; i < n; ++i) s[i] = std::sin(t[i]), c[i] = std::cos(t[i]);
}

}  // namespace kdl_space::detail
