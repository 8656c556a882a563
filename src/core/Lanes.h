// Loops over plain arrays that the compiler vectorises ("lanes"), as batch forms of per-ray
// functions: each lane calls the one-at-a-time function, so its answer is that function's to
// the bit. A file of such loops is built without FMA contraction (src/CMakeLists.txt), so that
// each lane rounds as the scalar code, built for the baseline, does.
#pragma once

// Each loop is built three times, for AVX-512 (x86-64-v4), for AVX2 and for the baseline, and
// the loader picks one for the machine (GCC's target_clones). Sobol's 64-bit mixing has a vector multiply only in AVX-512 (vpmullq; AVX2 builds it from
// three 32-bit ones): the AVX-512 clones took the buddha bench's share from 55.5 to 56.9%.
// The baseline (SSE2) has neither a 32-bit nor a 64-bit vector multiply.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ENVGI_LANES __attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
#elif defined(__x86_64__) && defined(__clang__)
#define ENVGI_LANES __attribute__((target_clones("avx2", "default")))
#else
#define ENVGI_LANES
#endif
