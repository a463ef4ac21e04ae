/*
 * lag_bus_init (server/wire/lagsim_bus.c) against the table every language's
 * implementation passes (tests/net/plant_urls.txt), and the channel names.
 *
 *   test_bus TABLE
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_bus.h"

static int failures, checks;
#define CHECK(c, ...)                                                                   \
    do {                                                                                \
        checks++;                                                                       \
        if (!(c)) {                                                                     \
            failures++;                                                                 \
            fprintf(stderr, "test_bus: FAIL line %d: ", __LINE__);                      \
            fprintf(stderr, __VA_ARGS__);                                               \
            fprintf(stderr, "\n");                                                      \
        }                                                                               \
    } while (0)

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\n' || s[n - 1] == '\r'))
        s[--n] = '\0';
    return s;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_bus TABLE\n");
        return 2;
    }
    unsetenv("LCM_DEFAULT_URL");
    FILE *f = fopen(argv[1], "r");
    if (!f) {
        perror(argv[1]);
        return 2;
    }
    char line[1024];
    int cases = 0;
    while (fgets(line, sizeof line, f)) {
        char *s = trim(line);
        if (*s == '\0' || *s == '#') continue;
        char *f1 = strstr(s, " | ");
        char *f2 = f1 ? strstr(f1 + 3, " | ") : NULL;
        if (!f1 || !f2) {
            fprintf(stderr, "test_bus: bad table line '%s'\n", s);
            return 2;
        }
        *f1 = *f2 = '\0';
        const char *base = trim(s), *want_state = trim(f1 + 3), *want_cmd = trim(f2 + 3);
        const char *url = strcmp(base, "(none)") == 0 ? NULL : base;
        lag_bus b;
        char err[256];
        int rc = lag_bus_init(&b, url, "DIPC", err, sizeof err);
        if (strcmp(want_state, "ERROR") == 0) {
            CHECK(rc == -1 && err[0], "'%s' accepted (%s, %s)", base, b.state_url, b.command_url);
        } else {
            CHECK(rc == 0, "'%s' refused: %s", base, err);
            CHECK(strcmp(b.state_url, want_state) == 0, "'%s': state url %s, expected %s", base,
                  b.state_url, want_state);
            CHECK(strcmp(b.command_url, want_cmd) == 0, "'%s': command url %s, expected %s", base,
                  b.command_url, want_cmd);
            CHECK(b.udpm == (strncmp(base, "memq", 4) != 0), "'%s': udpm flag", base);
        }
        cases++;
    }
    fclose(f);
    CHECK(cases >= 10, "only %d cases in the table", cases);

    /* the environment's default is the base when the URL is absent */
    setenv("LCM_DEFAULT_URL", "udpm://239.9.9.9:9000?ttl=1", 1);
    lag_bus b;
    char err[256];
    CHECK(lag_bus_init(&b, "", "X", err, sizeof err) == 0 &&
              strcmp(b.command_url, "udpm://239.9.9.9:9001?ttl=1") == 0,
          "LCM_DEFAULT_URL: %s", b.command_url);
    unsetenv("LCM_DEFAULT_URL");

    /* channels: the prefix and the suffix; inputs are the two the daemon receives */
    CHECK(lag_bus_init(&b, NULL, "RUN_7", err, sizeof err) == 0, "%s", err);
    const char *want[LAG_BUS_CHANNEL_COUNT] = {"RUN_7_STATE", "RUN_7_STATUS", "RUN_7_EVENT",
                                               "RUN_7_SCENE", "RUN_7_COMMAND", "RUN_7_CONTROL",
                                               "RUN_7_REFERENCE"};
    for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++) {
        CHECK(strcmp(b.channel[k], want[k]) == 0, "channel %d: %s", k, b.channel[k]);
        CHECK(lag_bus_is_input((lag_bus_channel)k) == (k == LAG_BUS_COMMAND || k == LAG_BUS_CONTROL), "input %d", k);
    }
    /* the longest prefix whose longest channel LCM takes (63 bytes), and one more */
    char p53[54];
    memset(p53, 'P', 53);
    p53[53] = '\0';
    CHECK(lag_bus_init(&b, NULL, p53, err, sizeof err) == 0 &&
              strlen(b.channel[LAG_BUS_REFERENCE]) == 63, "53-character prefix");
    size_t longest = 0;
    for (int k = 0; k < LAG_BUS_CHANNEL_COUNT; k++)
        if (strlen(b.channel[k]) > longest) longest = strlen(b.channel[k]);
    CHECK(longest == 63, "the longest channel of a 53-character prefix: %zu bytes", longest);
    char p54[55];
    memset(p54, 'P', 54);
    p54[54] = '\0';
    CHECK(lag_bus_init(&b, NULL, p54, err, sizeof err) == -1, "54-character prefix accepted");
    CHECK(lag_bus_init(&b, NULL, "", err, sizeof err) == -1, "empty prefix accepted");

    printf("test_bus: %d cases, %d checks, %d failures\n", cases, checks, failures);
    return failures ? 1 : 0;
}
