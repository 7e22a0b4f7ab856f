/* Throughput of a few AVX instructions on the machine at hand (eight independent chains per
 * instruction, so a result is the reciprocal throughput unless one op's latency exceeds eight
 * of them). Used in stop 18 to find what first-generation Zen charges for lane-crossing
 * shuffles, square roots and divisions.
 *
 *     cc -O2 benches/avx_op_costs.c -o /tmp/avx_op_costs && /tmp/avx_op_costs
 */
#include <stdio.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* Latencies (stop 23): one dependent chain. A square root or division alternates with a
 * multiply by 1.7, so the chain's values stay away from 1 (a square root of exactly 1 would
 * take a short cut); the multiply's own latency, measured alone, is subtracted. Both
 * registers are loaded in each block: the printf between blocks may clobber them. */
static void latencies(long n) {
    static const double c[4] = {1.7, 1.7, 1.7, 1.7};
    static const double inv_c[4] = {1 / 1.7, 1 / 1.7, 1 / 1.7, 1 / 1.7};
    static const double x0[4] = {2.3, 2.5, 2.7, 2.1};
    double t0, t1, mul;
    /* the multiplies alternate 1.7 and 1/1.7, so the chain stays finite */
    __asm__ volatile("vmovupd (%0),%%ymm1\n"
                     "vmovupd (%1),%%ymm2\n"
                     "vmovupd (%2),%%ymm3\n" ::"r"(x0), "r"(c), "r"(inv_c)
                     : "xmm1", "xmm2", "xmm3");
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vmulpd %%ymm2,%%ymm1,%%ymm1\n"
                         "vmulpd %%ymm3,%%ymm1,%%ymm1\n"
                         "vmulpd %%ymm2,%%ymm1,%%ymm1\n"
                         "vmulpd %%ymm3,%%ymm1,%%ymm1\n" ::: "xmm1");
    }
    t1 = now();
    mul = (t1 - t0) / n / 4 * 1e9;
    printf("latency, one dependent chain:\n");
    printf("%-38s %7.3f ns\n", "vmulpd ymm", mul);
#define LATENCY(name, op)                                                                       \
    __asm__ volatile("vmovupd (%0),%%ymm1\n"                                                   \
                     "vmovupd (%1),%%ymm2\n" ::"r"(x0), "r"(c)                                  \
                     : "xmm1", "xmm2");                                                         \
    t0 = now();                                                                                 \
    for (long i = 0; i < n; i++) {                                                              \
        __asm__ volatile(op "\n" ::: "xmm1", "xmm2");                                           \
    }                                                                                           \
    t1 = now();                                                                                 \
    printf("%-38s %7.3f ns\n", name, (t1 - t0) / n * 1e9 - mul);
    LATENCY("vsqrtpd ymm", "vsqrtpd %%ymm1,%%ymm1\n vmulpd %%ymm2,%%ymm1,%%ymm1")
    LATENCY("vsqrtpd xmm", "vsqrtpd %%xmm1,%%xmm1\n vmulpd %%xmm2,%%xmm1,%%xmm1")
    LATENCY("vdivpd ymm", "vdivpd %%ymm1,%%ymm2,%%ymm1\n vmulpd %%ymm2,%%ymm1,%%ymm1")
    LATENCY("vdivpd xmm", "vdivpd %%xmm1,%%xmm2,%%xmm1\n vmulpd %%xmm2,%%xmm1,%%xmm1")
#undef LATENCY
}

int main(void) {
    static const double v[4] = {1.234e-7, 2.3e-7, 3.1e-7, 7.7e-8};
    static const double w[4] = {0.7, 1.3, 2.9, 0.11};
    const long n = 20000000;
    double t0, t1, mul;
    __asm__ volatile("vxorpd %%ymm8,%%ymm8,%%ymm8\n"
                     "vmovupd (%0),%%ymm9\n"
                     "vmovupd (%1),%%ymm10\n" ::"r"(v), "r"(w)
                     : "xmm8", "xmm9", "xmm10");
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vmulpd %%ymm8,%%ymm0,%%ymm0\n"
                         "vmulpd %%ymm8,%%ymm1,%%ymm1\n"
                         "vmulpd %%ymm8,%%ymm2,%%ymm2\n"
                         "vmulpd %%ymm8,%%ymm3,%%ymm3\n"
                         "vmulpd %%ymm8,%%ymm4,%%ymm4\n"
                         "vmulpd %%ymm8,%%ymm5,%%ymm5\n"
                         "vmulpd %%ymm8,%%ymm6,%%ymm6\n"
                         "vmulpd %%ymm8,%%ymm7,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    mul = (t1 - t0) / n / 8 * 1e9;
    printf("%-38s %7.3f ns/op  (1.00 vmulpd)\n", "vmulpd ymm", mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vperm2f128 $0x21,%%ymm8,%%ymm0,%%ymm0\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm1,%%ymm1\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm2,%%ymm2\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm3,%%ymm3\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm4,%%ymm4\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm5,%%ymm5\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm6,%%ymm6\n"
                         "vperm2f128 $0x21,%%ymm8,%%ymm7,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vperm2f128 $0x21 (lane-crossing)", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vinsertf128 $1,%%xmm8,%%ymm0,%%ymm0\n"
                         "vinsertf128 $1,%%xmm8,%%ymm1,%%ymm1\n"
                         "vinsertf128 $1,%%xmm8,%%ymm2,%%ymm2\n"
                         "vinsertf128 $1,%%xmm8,%%ymm3,%%ymm3\n"
                         "vinsertf128 $1,%%xmm8,%%ymm4,%%ymm4\n"
                         "vinsertf128 $1,%%xmm8,%%ymm5,%%ymm5\n"
                         "vinsertf128 $1,%%xmm8,%%ymm6,%%ymm6\n"
                         "vinsertf128 $1,%%xmm8,%%ymm7,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vinsertf128 $1 (xmm into upper half)", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vunpcklpd %%ymm8,%%ymm0,%%ymm0\n"
                         "vunpcklpd %%ymm8,%%ymm1,%%ymm1\n"
                         "vunpcklpd %%ymm8,%%ymm2,%%ymm2\n"
                         "vunpcklpd %%ymm8,%%ymm3,%%ymm3\n"
                         "vunpcklpd %%ymm8,%%ymm4,%%ymm4\n"
                         "vunpcklpd %%ymm8,%%ymm5,%%ymm5\n"
                         "vunpcklpd %%ymm8,%%ymm6,%%ymm6\n"
                         "vunpcklpd %%ymm8,%%ymm7,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vunpcklpd (in-lane)", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vpermpd $0x4e,%%ymm0,%%ymm0\n"
                         "vpermpd $0x4e,%%ymm1,%%ymm1\n"
                         "vpermpd $0x4e,%%ymm2,%%ymm2\n"
                         "vpermpd $0x4e,%%ymm3,%%ymm3\n"
                         "vpermpd $0x4e,%%ymm4,%%ymm4\n"
                         "vpermpd $0x4e,%%ymm5,%%ymm5\n"
                         "vpermpd $0x4e,%%ymm6,%%ymm6\n"
                         "vpermpd $0x4e,%%ymm7,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vpermpd $0x4e", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vaddpd %%ymm8,%%ymm0,%%ymm0\n"
                         "vaddpd %%ymm8,%%ymm1,%%ymm1\n"
                         "vaddpd %%ymm8,%%ymm2,%%ymm2\n"
                         "vaddpd %%ymm8,%%ymm3,%%ymm3\n"
                         "vaddpd %%ymm8,%%ymm4,%%ymm4\n"
                         "vaddpd %%ymm8,%%ymm5,%%ymm5\n"
                         "vaddpd %%ymm8,%%ymm6,%%ymm6\n"
                         "vaddpd %%ymm8,%%ymm7,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vaddpd ymm", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vsqrtpd %%ymm9,%%ymm0\n"
                         "vsqrtpd %%ymm9,%%ymm1\n"
                         "vsqrtpd %%ymm9,%%ymm2\n"
                         "vsqrtpd %%ymm9,%%ymm3\n"
                         "vsqrtpd %%ymm9,%%ymm4\n"
                         "vsqrtpd %%ymm9,%%ymm5\n"
                         "vsqrtpd %%ymm9,%%ymm6\n"
                         "vsqrtpd %%ymm9,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vsqrtpd ymm", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vsqrtpd %%xmm9,%%xmm0\n"
                         "vsqrtpd %%xmm9,%%xmm1\n"
                         "vsqrtpd %%xmm9,%%xmm2\n"
                         "vsqrtpd %%xmm9,%%xmm3\n"
                         "vsqrtpd %%xmm9,%%xmm4\n"
                         "vsqrtpd %%xmm9,%%xmm5\n"
                         "vsqrtpd %%xmm9,%%xmm6\n"
                         "vsqrtpd %%xmm9,%%xmm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vsqrtpd xmm", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vsqrtsd %%xmm9,%%xmm9,%%xmm0\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm1\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm2\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm3\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm4\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm5\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm6\n"
                         "vsqrtsd %%xmm9,%%xmm9,%%xmm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vsqrtsd", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vdivpd %%ymm10,%%ymm9,%%ymm0\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm1\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm2\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm3\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm4\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm5\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm6\n"
                         "vdivpd %%ymm10,%%ymm9,%%ymm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vdivpd ymm", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    t0 = now();
    for (long i = 0; i < n; i++) {
        __asm__ volatile("vdivpd %%xmm10,%%xmm9,%%xmm0\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm1\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm2\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm3\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm4\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm5\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm6\n"
                         "vdivpd %%xmm10,%%xmm9,%%xmm7\n"
                         ::: "xmm0", "xmm1", "xmm2", "xmm3", "xmm4", "xmm5", "xmm6", "xmm7");
    }
    t1 = now();
    printf("%-38s %7.3f ns/op  (%.2f vmulpd)\n", "vdivpd xmm", (t1 - t0) / n / 8 * 1e9,
           (t1 - t0) / n / 8 * 1e9 / mul);
    latencies(n);
    return 0;
}
