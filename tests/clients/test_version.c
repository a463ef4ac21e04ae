/*
 * One version, from project(VERSION) in CMakeLists.txt: the macros of lagsim/version.h,
 * the core's lag_version() and the client library's lag_client_version() (this program
 * links liblagsim_client.so, so it is the shared library's answer) all say it, and the
 * ABI number the library was built with is the header's.
 *
 * usage: test_version versions PROJECT_VERSION CLIENT_ABI   (tests/common/lagsim_test.h)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim.h"
#include "lagsim_client.h"
#include "lagsim_test.h"

static void case_versions(int arg)
{
    (void)arg;
    int major = -1, minor = -1, patch = -1;
    ENSUREF(sscanf(lt_arg(0), "%d.%d.%d", &major, &minor, &patch) == 3,
            "project(VERSION) %s is not MAJOR.MINOR.PATCH", lt_arg(0));
    ENSUREF(LAGSIM_VERSION_MAJOR == major && LAGSIM_VERSION_MINOR == minor &&
                LAGSIM_VERSION_PATCH == patch && !strcmp(LAGSIM_VERSION_STRING, lt_arg(0)),
            "lagsim/version.h says %d.%d.%d (%s), project(VERSION) %s", LAGSIM_VERSION_MAJOR,
            LAGSIM_VERSION_MINOR, LAGSIM_VERSION_PATCH, LAGSIM_VERSION_STRING, lt_arg(0));
    const int number = major * 1000000 + minor * 1000 + patch;
    ENSUREF(LAGSIM_VERSION_NUMBER == number, "LAGSIM_VERSION_NUMBER %d, not %d",
            LAGSIM_VERSION_NUMBER, number);
    ENSUREF(lag_version() == number, "the core's lag_version() %d, not %d", lag_version(),
            number);
    ENSUREF(lag_client_version() == number, "the client library's lag_client_version() %d, not %d",
            lag_client_version(), number);
    ENSUREF(LAGSIM_CLIENT_ABI == atoi(lt_arg(1)) && lag_client_abi() == LAGSIM_CLIENT_ABI,
            "ABI: header %d, library %d, CMakeLists.txt %s", LAGSIM_CLIENT_ABI,
            lag_client_abi(), lt_arg(1));
    /* versions compare as numbers: 0.10.0 after 0.9.9 */
    ENSURE(0 * 1000000 + 10 * 1000 + 0 > 0 * 1000000 + 9 * 1000 + 9);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"versions", case_versions, 0, 0}};
    const lt_program p = {.cases = cases, .n = 1, .args = "PROJECT_VERSION CLIENT_ABI",
                          .min_args = 2, .max_args = 2};
    return lt_run(argc, argv, &p);
}
