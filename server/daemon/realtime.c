/* Placeholder until the real-time server lands: reports that it is missing. */
#include <stdio.h>
#include "daemon.h"

int lagsimd_realtime(const lag_scene *sc, const lagsimd_opts *o)
{
    (void)sc; (void)o;
    fprintf(stderr, "lagsimd: real-time mode is not built yet\n");
    return LAGSIMD_EXIT_RUNTIME;
}

int lagsimd_replay(const lag_scene *sc, const char *log_path, const lagsimd_opts *o)
{
    (void)sc; (void)log_path; (void)o;
    fprintf(stderr, "lagsimd: --replay is not built yet\n");
    return LAGSIMD_EXIT_RUNTIME;
}
