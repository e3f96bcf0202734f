/* Runtime of eomgen's fast backend: FMA_CLONES, the attribute of the long kernels (issue 42:
 * the build compiles them as translation units of their own, which begin with this text too).
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles it on its own with -Wall -Wextra -Werror. */

/* eomgen: the generated module holds the text below this line. */
/* The kernels marked FMA_CLONES (the longest: their arithmetic, not the call, is the time) are
 * compiled twice, with and without fused multiply-add instructions, and the loader picks the
 * version this CPU runs (target_clones; x86-64 Linux with glibc, else one plain version). */
#if defined(__x86_64__) && defined(__linux__) && defined(__GLIBC__) && defined(__has_attribute)
#if __has_attribute(target_clones)
#define FMA_CLONES __attribute__((target_clones("fma", "default")))
#endif
#endif
#ifndef FMA_CLONES
#define FMA_CLONES
#endif
