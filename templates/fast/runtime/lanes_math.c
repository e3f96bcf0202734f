/* Runtime of eomgen's fast backend: sine and cosine of a vector of EOM_LANES doubles (a lanes
 * kernel's: one state per lane) in SIMD arithmetic, without a libm call per lane.
 *
 * x = k pi/2 + r with k = round(x 2/pi) and |r| <= pi/4 (Cody-Waite: pi/2 in three parts of
 * 33 bits and a double, so that k times each of the first two is exact for |k| < 2^20; r a sum of two
 * doubles), then sin r and cos r by polynomials in z = r^2 (coefficients: Chebyshev fits of
 * (sin r - r)/r^3 and (cos r - 1 + z/2)/z^2 over z <= (pi/4)^2, errors 2e-17 and 1.3e-18, made
 * for eomgen with mpmath), and the quadrant k mod 4 choosing and signing them. Error against
 * libm: at most 2 ulp for |x| <= 1e5 (docs/numerics.md; tests/backends/test_fast_runtime_c.py
 * measures it on many points); beyond 1e5, and for nan or +-inf, every lane of the vector goes
 * through libm's sin and cos. sin and cos of the same x share their reduction (GCC and Clang
 * merge the two inlined copies).
 *
 * The generated module defines eom_lanes (call.c) before this text; the lines above the
 * marker let the file compile alone. */
#include <math.h>
#define EOM_LANES 4
typedef double eom_lanes __attribute__((vector_size(8 * EOM_LANES)));

/* eomgen: the generated module holds the text below this line. */
typedef unsigned long long eom_lane_bits __attribute__((vector_size(8 * EOM_LANES)));
typedef long long eom_lane_ints __attribute__((vector_size(8 * EOM_LANES)));

#define EOM_PIO2_1 0x1.921fb544p+0           /* pi/2 = EOM_PIO2_1 + EOM_PIO2_2 + EOM_PIO2_3 + */
#define EOM_PIO2_2 0x1.0b4611a6p-34          /* O(2^-122): two parts of 33 bits, one of 53 */
#define EOM_PIO2_3 0x1.3198a2e037073p-69
#define EOM_2_OVER_PI 0x1.45f306dc9c883p-1
#define EOM_ROUND 0x1.8p52                    /* (y + EOM_ROUND) - EOM_ROUND: y rounded */
#define EOM_REDUCE_LIMIT 1e5                  /* beyond: libm, lane by lane */
#define EOM_INLINE inline __attribute__((always_inline))

/* sin and cos of every lane of *at (vectors by pointer: none crosses a call by value, whose
 * ABI depends on the instruction set). */
static EOM_INLINE void eom_sincos_lanes(const eom_lanes *at, eom_lanes *sine, eom_lanes *cosine)
{
    const eom_lanes x = *at;
    const eom_lanes k = (x * EOM_2_OVER_PI + EOM_ROUND) - EOM_ROUND;
    const eom_lane_bits n = (eom_lane_bits)__builtin_convertvector(k, eom_lane_ints);
    /* |x| > EOM_REDUCE_LIMIT, nan or +-inf: the bits without the sign, compared unsigned */
    const eom_lane_ints far = ((eom_lane_bits)x << 1)
        > ((eom_lane_bits)((eom_lanes){0} + EOM_REDUCE_LIMIT) << 1);
    /* r_hi + r_lo = x - k pi/2: a exact, w exact, (a - r1) - w the rounding error of r1 */
    const eom_lanes a = x - k * EOM_PIO2_1;
    const eom_lanes w = k * EOM_PIO2_2;
    const eom_lanes r1 = a - w;
    const eom_lanes t = ((a - r1) - w) - k * EOM_PIO2_3;
    const eom_lanes r = r1 + t;
    const eom_lanes r_lo = (r1 - r) + t;
    const eom_lanes z = r * r;
    /* sin(r + r_lo) = r + r z S(z) + r_lo (1 - z/2); cos(r + r_lo) = 1 - z/2 + z^2 C(z) - r r_lo,
     * 1 - z/2 as w_c plus its rounding error */
    const eom_lanes s_poly = -0x1.5555555555555p-3 + z * (0x1.1111111110babp-7 + z * (
        -0x1.a01a019e820aep-13 + z * (0x1.71de37946ed6dp-19 + z * (-0x1.ae6008d114485p-26
        + z * 0x1.5e0a4fc16be59p-33))));
    const eom_lanes c_poly = 0x1.5555555555555p-5 + z * (-0x1.6c16c16c16963p-10 + z * (
        0x1.a01a019f4ddfdp-16 + z * (-0x1.27e4fa16cc2d1p-22 + z * (0x1.1eeb67d026ec6p-29
        + z * -0x1.907cd8ff5ede7p-37))));
    const eom_lanes half_z = 0.5 * z;
    const eom_lanes w_c = 1.0 - half_z;
    const eom_lanes s = r + ((r * z) * s_poly + r_lo * w_c);
    const eom_lanes c = w_c + (((1.0 - w_c) - half_z) + ((z * z) * c_poly - r * r_lo));
    /* quadrant n mod 4: sin x = s, c, -s, -c; cos x = c, -s, -c, s */
    const eom_lane_bits swap = -(n & 1);
    const eom_lane_bits sin_bits = (((eom_lane_bits)s & ~swap) | ((eom_lane_bits)c & swap))
        ^ ((n & 2) << 62);
    const eom_lane_bits cos_bits = (((eom_lane_bits)c & ~swap) | ((eom_lane_bits)s & swap))
        ^ (((n + 1) & 2) << 62);
    long long any = 0;
    int l;
    *sine = (eom_lanes)sin_bits;
    *cosine = (eom_lanes)cos_bits;
    for (l = 0; l < EOM_LANES; ++l)
        any |= far[l];
    if (__builtin_expect(any != 0, 0))
        for (l = 0; l < EOM_LANES; ++l) {
            (*sine)[l] = sin(x[l]);
            (*cosine)[l] = cos(x[l]);
        }
}

/* sin(value) and cos(value) of a lanes kernel (GNU statement expressions). */
#define EOM_SIN_LANES(value) ({ \
    eom_lanes eom_x = (value), eom_sine, eom_cosine; \
    eom_sincos_lanes(&eom_x, &eom_sine, &eom_cosine); \
    eom_sine; })
#define EOM_COS_LANES(value) ({ \
    eom_lanes eom_x = (value), eom_sine, eom_cosine; \
    eom_sincos_lanes(&eom_x, &eom_sine, &eom_cosine); \
    eom_cosine; })
