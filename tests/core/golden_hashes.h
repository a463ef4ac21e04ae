/* Golden hashes of tests/core/test_determinism.c (golden_<model>): one row per (libm,
 * model, method, scene). Recorded with
 *   LAGSIM_PRINT_GOLDEN=1 build/bin/test_core_determinism golden_<model>
 * and, for glibc's implementation without FMA on the same machine,
 *   GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX2,-FMA LAGSIM_PRINT_GOLDEN=1 build/bin/...
 * A new model adds its rows (for each libm); a change that alters trajectories on purpose
 * records new values and says why in its commit. */
#ifndef LAGSIM_GOLDEN_HASHES_H
#define LAGSIM_GOLDEN_HASHES_H
#include <stdint.h>

/* The libms goldens are recorded for, by fingerprint (see libm_fingerprint). */
static const struct golden_libm {
    uint64_t fingerprint;
    const char *what;
} golden_libms[] = {
    {0x997cc7d2186dc6cbull, "glibc 2.36, x86-64, FMA/AVX2 implementation"},
    {0x94ea8925ffd7f1f0ull, "glibc 2.36, x86-64, implementation without FMA/AVX2"},
};

typedef struct golden_hash {
    uint64_t libm;
    const char *model, *method, *scene;
    uint64_t hash;
} golden_hash;

static const golden_hash golden_hashes[] = {
    {0x997cc7d2186dc6cbull, "stick", "euler", "bare", 0xeec144047034f19dull},
    {0x997cc7d2186dc6cbull, "stick", "euler", "effects", 0x4914fa99b8343489ull},
    {0x997cc7d2186dc6cbull, "stick", "semi-implicit-euler", "bare", 0x1e4161bba2b2503dull},
    {0x997cc7d2186dc6cbull, "stick", "semi-implicit-euler", "effects", 0x4e2736cee4e5740full},
    {0x997cc7d2186dc6cbull, "stick", "rk4", "bare", 0x3b64ed5a674a9f95ull},
    {0x997cc7d2186dc6cbull, "stick", "rk4", "effects", 0x65a436107936a8dbull},
    {0x997cc7d2186dc6cbull, "stick", "dopri5", "bare", 0xd92034125579b4d9ull},
    {0x997cc7d2186dc6cbull, "stick", "dopri5", "effects", 0x4e511675ff9d9e74ull},
    {0x997cc7d2186dc6cbull, "stick", "implicit-midpoint", "bare", 0x7abef006889b03f9ull},
    {0x997cc7d2186dc6cbull, "stick", "implicit-midpoint", "effects", 0xee39516f1e2de3f6ull},
    {0x997cc7d2186dc6cbull, "stick", "gauss4", "bare", 0xe83daf9c20d8d6a1ull},
    {0x997cc7d2186dc6cbull, "stick", "gauss4", "effects", 0x8bd616351972e18bull},
    {0x997cc7d2186dc6cbull, "manipulator", "euler", "bare", 0x0f83efbb84d4f8d9ull},
    {0x997cc7d2186dc6cbull, "manipulator", "euler", "effects", 0xc316b2009dfed908ull},
    {0x997cc7d2186dc6cbull, "manipulator", "semi-implicit-euler", "bare", 0xf46699832ab49e9dull},
    {0x997cc7d2186dc6cbull, "manipulator", "semi-implicit-euler", "effects", 0x5f6393f34e85d2cbull},
    {0x997cc7d2186dc6cbull, "manipulator", "rk4", "bare", 0x774dc1110344a975ull},
    {0x997cc7d2186dc6cbull, "manipulator", "rk4", "effects", 0x48eab15a89f237d1ull},
    {0x997cc7d2186dc6cbull, "manipulator", "dopri5", "bare", 0xb8c994c8bfdd5079ull},
    {0x997cc7d2186dc6cbull, "manipulator", "dopri5", "effects", 0x6c4157f775b0a043ull},
    {0x997cc7d2186dc6cbull, "manipulator", "implicit-midpoint", "bare", 0x563583b61ac7caedull},
    {0x997cc7d2186dc6cbull, "manipulator", "implicit-midpoint", "effects", 0x010c2bb9742e4939ull},
    {0x997cc7d2186dc6cbull, "manipulator", "gauss4", "bare", 0x58a80283ed6e3c11ull},
    {0x997cc7d2186dc6cbull, "manipulator", "gauss4", "effects", 0x8c00cfbf2c5733f2ull},
    {0x997cc7d2186dc6cbull, "dipc", "euler", "bare", 0x8200df5cceb75699ull},
    {0x997cc7d2186dc6cbull, "dipc", "euler", "effects", 0x7cbb51466c32452full},
    {0x997cc7d2186dc6cbull, "dipc", "semi-implicit-euler", "bare", 0xfa54a71a0e486015ull},
    {0x997cc7d2186dc6cbull, "dipc", "semi-implicit-euler", "effects", 0x3c67044174f41f73ull},
    {0x997cc7d2186dc6cbull, "dipc", "rk4", "bare", 0x473c8ed7ddee86e5ull},
    {0x997cc7d2186dc6cbull, "dipc", "rk4", "effects", 0x553ba66e96cf2f53ull},
    {0x997cc7d2186dc6cbull, "dipc", "dopri5", "bare", 0x4f6e459e150fc351ull},
    {0x997cc7d2186dc6cbull, "dipc", "dopri5", "effects", 0x8f2d9dd377571642ull},
    {0x997cc7d2186dc6cbull, "dipc", "implicit-midpoint", "bare", 0xa7c9f8392ad98921ull},
    {0x997cc7d2186dc6cbull, "dipc", "implicit-midpoint", "effects", 0x8cc1db83a74d6824ull},
    {0x997cc7d2186dc6cbull, "dipc", "gauss4", "bare", 0xeec2e431316ed1c1ull},
    {0x997cc7d2186dc6cbull, "dipc", "gauss4", "effects", 0x24f493497175a6deull},
    {0x94ea8925ffd7f1f0ull, "stick", "euler", "bare", 0xeec144047034f19dull},
    {0x94ea8925ffd7f1f0ull, "stick", "euler", "effects", 0x4914fa99b8343489ull},
    {0x94ea8925ffd7f1f0ull, "stick", "semi-implicit-euler", "bare", 0x1e4161bba2b2503dull},
    {0x94ea8925ffd7f1f0ull, "stick", "semi-implicit-euler", "effects", 0x4e2736cee4e5740full},
    {0x94ea8925ffd7f1f0ull, "stick", "rk4", "bare", 0x3b64ed5a674a9f95ull},
    {0x94ea8925ffd7f1f0ull, "stick", "rk4", "effects", 0x65a436107936a8dbull},
    {0x94ea8925ffd7f1f0ull, "stick", "dopri5", "bare", 0x7a0a0953bdc00609ull},
    {0x94ea8925ffd7f1f0ull, "stick", "dopri5", "effects", 0x4e511675ff9d9e74ull},
    {0x94ea8925ffd7f1f0ull, "stick", "implicit-midpoint", "bare", 0x7abef006889b03f9ull},
    {0x94ea8925ffd7f1f0ull, "stick", "implicit-midpoint", "effects", 0xee39516f1e2de3f6ull},
    {0x94ea8925ffd7f1f0ull, "stick", "gauss4", "bare", 0xe83daf9c20d8d6a1ull},
    {0x94ea8925ffd7f1f0ull, "stick", "gauss4", "effects", 0x8bd616351972e18bull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "euler", "bare", 0x0f83efbb84d4f8d9ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "euler", "effects", 0xc316b2009dfed908ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "semi-implicit-euler", "bare", 0xf46699832ab49e9dull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "semi-implicit-euler", "effects", 0x5f6393f34e85d2cbull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "rk4", "bare", 0x774dc1110344a975ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "rk4", "effects", 0x48eab15a89f237d1ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "dopri5", "bare", 0x0d722f0dd56c83e1ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "dopri5", "effects", 0x6c4157f775b0a043ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "implicit-midpoint", "bare", 0x563583b61ac7caedull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "implicit-midpoint", "effects", 0x010c2bb9742e4939ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "gauss4", "bare", 0x58a80283ed6e3c11ull},
    {0x94ea8925ffd7f1f0ull, "manipulator", "gauss4", "effects", 0x8c00cfbf2c5733f2ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "euler", "bare", 0x8200df5cceb75699ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "euler", "effects", 0x7cbb51466c32452full},
    {0x94ea8925ffd7f1f0ull, "dipc", "semi-implicit-euler", "bare", 0x84af564213aee42dull},
    {0x94ea8925ffd7f1f0ull, "dipc", "semi-implicit-euler", "effects", 0x3c67044174f41f73ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "rk4", "bare", 0x473c8ed7ddee86e5ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "rk4", "effects", 0x553ba66e96cf2f53ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "dopri5", "bare", 0xae0c115e12fa2b09ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "dopri5", "effects", 0x3c617ddcf0a66697ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "implicit-midpoint", "bare", 0xc90013f1b3f5d005ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "implicit-midpoint", "effects", 0x6c3d1d0e7625d4cdull},
    {0x94ea8925ffd7f1f0ull, "dipc", "gauss4", "bare", 0x0ecb1c93117e4459ull},
    {0x94ea8925ffd7f1f0ull, "dipc", "gauss4", "effects", 0x24f493497175a6deull},
    {0x997cc7d2186dc6cbull, "cartpole", "euler", "bare", 0xc3f6ecdc230b73d1ull},
    {0x997cc7d2186dc6cbull, "cartpole", "euler", "effects", 0x0b060ef90c5d2f93ull},
    {0x997cc7d2186dc6cbull, "cartpole", "semi-implicit-euler", "bare", 0x2af5ed3334d04191ull},
    {0x997cc7d2186dc6cbull, "cartpole", "semi-implicit-euler", "effects", 0xa1ae38811a441521ull},
    {0x997cc7d2186dc6cbull, "cartpole", "rk4", "bare", 0x9cb4edeed3abf925ull},
    {0x997cc7d2186dc6cbull, "cartpole", "rk4", "effects", 0x80e0e70ed6386665ull},
    {0x997cc7d2186dc6cbull, "cartpole", "dopri5", "bare", 0xd9d7f9ba75f12eb1ull},
    {0x997cc7d2186dc6cbull, "cartpole", "dopri5", "effects", 0x5e0a9c947a841b1aull},
    {0x997cc7d2186dc6cbull, "cartpole", "implicit-midpoint", "bare", 0xf67c096b7c83e04dull},
    {0x997cc7d2186dc6cbull, "cartpole", "implicit-midpoint", "effects", 0x5886397424a1123cull},
    {0x997cc7d2186dc6cbull, "cartpole", "gauss4", "bare", 0x7886ef66adbd10b9ull},
    {0x997cc7d2186dc6cbull, "cartpole", "gauss4", "effects", 0x5da6d090c6c1c7e6ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "euler", "bare", 0x0ebb6881263506a5ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "euler", "effects", 0x0b060ef90c5d2f93ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "semi-implicit-euler", "bare", 0x2af5ed3334d04191ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "semi-implicit-euler", "effects", 0xa1ae38811a441521ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "rk4", "bare", 0x9cb4edeed3abf925ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "rk4", "effects", 0x80e0e70ed6386665ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "dopri5", "bare", 0x42b7be88b1aa59e1ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "dopri5", "effects", 0x5e0a9c947a841b1aull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "implicit-midpoint", "bare", 0xf67c096b7c83e04dull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "implicit-midpoint", "effects", 0x5886397424a1123cull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "gauss4", "bare", 0x7886ef66adbd10b9ull},
    {0x94ea8925ffd7f1f0ull, "cartpole", "gauss4", "effects", 0x5da6d090c6c1c7e6ull},
};

#endif
