/* Runtime of eomgen's fast backend: what a lanes kernel is written with (EOM_BROADCAST; sin and
 * cos by lanes_math.c's vector routine, sqrt lane by lane), included where a module has lanes
 * kernels, after the call runtime's eom_lanes and lanes_math.c, inside #if EOM_LANES > 1 (and
 * at the head of a translation unit that holds one, issue 42).
 *
 * Real C source, not a template: eomgen copies the text below the marker line into the module
 * (eomgen.codegen.backends.fast_backend.runtime_source), and tests/test_fast_runtime_c.py
 * compiles it on its own with -Wall -Wextra -Werror. */
#include <math.h>

/* eomgen: the generated module holds the text below this line. */
/* The lanes kernels of a batch (in_lanes): the one-state kernels' arithmetic on vectors of
 * EOM_LANES states, sin and cos by the vector routine above, sqrt lane by lane (a statement
 * expression: no vector crosses a function call); a constant is broadcast to every lane. Every
 * kernel of LANES_OPERATIONS to LANES_MAX_OPERATIONS operations (eomgen's fast backend) whose
 * arithmetic is +, -, *, / and those functions has one, compiled with and without FMA
 * (FMA_CLONES). */
#define EOM_BROADCAST(value) ((value) - (eom_lanes){0})
#define EOM_LANES_KERNEL(kernel) kernel
#define EOM_EACH_LANE(function, value) ({ \
    eom_lanes eom_each = (value); \
    for (int eom_l = 0; eom_l < EOM_LANES; ++eom_l) \
        eom_each[eom_l] = function(eom_each[eom_l]); \
    eom_each; })
#define sin(value) EOM_SIN_LANES(value)
#define cos(value) EOM_COS_LANES(value)
#define sqrt(value) EOM_EACH_LANE(sqrt, value)
