/*
 * lag_bus_init (server/wire/lagsim_bus.c) against the table every language's
 * implementation passes (tests/net/plant_urls.txt), and the channel names.
 *
 *   test_bus plant_urls_c TABLE   (tests/common/lagsim_test.h)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_bus.h"
#include "lagsim_test.h"

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' || s[n - 1] == '\r'))
        s[--n] = '\0';
    return s;
}

static void case_plant_urls_c(int arg)
{
    (void)arg;
    unsetenv("LCM_DEFAULT_URL");
    FILE *f = fopen(lt_arg(0), "r");
    ENSUREF(f, "cannot open %s", lt_arg(0));
    if (!f) return;
    char line[1024];
    int cases = 0;
    while (fgets(line, sizeof line, f)) {
        char *s = trim(line);
        if (*s == '\0' || *s == '#') continue;
        char *f1 = strstr(s, " | ");
        char *f2 = f1 ? strstr(f1 + 3, " | ") : NULL;
        ENSUREF(f1 && f2, "bad table line '%s'", s);
        if (!f1 || !f2) break;
        *f1 = *f2 = '\0';
        const char *base = trim(s), *want_state = trim(f1 + 3), *want_cmd = trim(f2 + 3);
        const char *url = strcmp(base, "(none)") == 0 ? NULL : base;
        lag_bus b;
        char err[256];
        int rc = lag_bus_init(&b, url, "DIPC", err, sizeof err);
        if (strcmp(want_state, "ERROR") == 0) {
            ENSUREF(rc == -1 && err[0], "'%s' accepted (%s, %s)", base, b.state_url, b.command_url);
        } else {
            ENSUREF(rc == 0, "'%s' refused: %s", base, err);
            ENSUREF(strcmp(b.state_url, want_state) == 0, "'%s': state url %s, expected %s", base,
                  b.state_url, want_state);
            ENSUREF(strcmp(b.command_url, want_cmd) == 0, "'%s': command url %s, expected %s", base,
                  b.command_url, want_cmd);
            ENSUREF(b.udpm == (strncmp(base, "memq", 4) != 0), "'%s': udpm flag", base);
        }
        cases++;
    }
    fclose(f);
    ENSUREF(cases >= 10, "only %d cases in the table", cases);

    /* the environment's default is the base when the URL is absent */
    setenv("LCM_DEFAULT_URL", "udpm://239.9.9.9:9000?ttl=1", 1);
    lag_bus b;
    char err[256];
    ENSUREF(lag_bus_init(&b, "", "X", err, sizeof err) == 0 &&
              strcmp(b.command_url, "udpm://239.9.9.9:9001?ttl=1") == 0,
          "LCM_DEFAULT_URL: %s", b.command_url);
    unsetenv("LCM_DEFAULT_URL");

    /* channels: the prefix and the suffix; inputs are the two the daemon receives */
    ENSUREF(lag_bus_init(&b, NULL, "RUN_7", err, sizeof err) == 0, "%s", err);
    const char *want[LAG_BUS_CHANNEL_COUNT] = {"RUN_7_STATE", "RUN_7_STATUS", "RUN_7_EVENT",
                                               "RUN_7_SCENE", "RUN_7_COMMAND", "RUN_7_CONTROL",
                                               "RUN_7_REFERENCE"};
    for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++) {
        ENSUREF(strcmp(b.channel[k], want[k]) == 0, "channel %d: %s", k, b.channel[k]);
        ENSUREF(lag_bus_is_input((lag_bus_channel)k) == (k == LAG_BUS_COMMAND || k == LAG_BUS_CONTROL), "input %d", k);
    }
    /* the longest prefix whose longest channel LCM takes (63 bytes), and one more */
    char p53[54];
    memset(p53, 'P', 53);
    p53[53] = '\0';
    ENSUREF(lag_bus_init(&b, NULL, p53, err, sizeof err) == 0 &&
              strlen(b.channel[LAG_BUS_REFERENCE]) == 63, "53-character prefix");
    size_t longest = 0;
    for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++)
        if (strlen(b.channel[k]) > longest) longest = strlen(b.channel[k]);
    ENSUREF(longest == 63, "the longest channel of a 53-character prefix: %zu bytes", longest);
    char p54[55];
    memset(p54, 'P', 54);
    p54[54] = '\0';
    ENSUREF(lag_bus_init(&b, NULL, p54, err, sizeof err) == -1, "54-character prefix accepted");
    ENSUREF(lag_bus_init(&b, NULL, "", err, sizeof err) == -1, "empty prefix accepted");

    printf("test_bus: %d cases of the table\n", cases);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"plant_urls_c", case_plant_urls_c, 0, 0}};
    const lt_program p = {.cases = cases, .n = 1, .args = "TABLE", .min_args = 1, .max_args = 1};
    return lt_run(argc, argv, &p);
}
