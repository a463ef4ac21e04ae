/*
 * lagsim-sweep's CSV (server/tools/sweep_merge.h) without a sweep: the check of a row
 * against its header (every malformed row merge must refuse, and the rows the writer
 * writes), the reason as the writer quotes it, --shard's parser, the header's columns, the
 * identity lines and the scene's SHA-256 against the FIPS 180-2 test vectors; the reason
 * a --require gives (every term that fails, as the reason column of both tools holds it).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lagsim_test.h"
#include "sweep_merge.h"

/* run, two varied keys, the verdict, two metrics; 8 runs */
#define HEADER "run,parameters.m0,initial.q[1],failed,required,reason,x.rise,x.settle"
#define RUNS 8

static sweep_columns cols;

static void columns(void)
{
    char why[256];
    ENSUREF(sweep_columns_parse(HEADER, 2, &cols, why, sizeof why) == 0, "%s", why);
    ENSURE(cols.n == 8 && !strcmp(cols.name[7], "x.settle"));
}

/* line (len bytes) checked: NULL for a row that passes with run `want`, else a text the
 * reason must hold */
static void row(const char *line, size_t len, long want, const char *fault)
{
    char why[512] = "";
    long run = -7;
    int rc = sweep_row_check(&cols, line, len, RUNS, &run, why, sizeof why);
    if (!fault)
        ENSUREF(rc == 0 && run == want, "'%.*s': %s (run %ld)", (int)len, line, why, run);
    else
        ENSUREF(rc == -1 && strstr(why, fault), "'%.*s': expected '%s', got %d '%s'",
                (int)len, line, fault, rc, why);
}

#define ROW(text, want, fault) row(text, strlen(text), want, fault)

static void case_rows(int arg)
{
    (void)arg;
    columns();
    /* rows as lagsim-sweep writes them */
    ROW("3,1.4140917868522627,0.050000000000000003,0,1,\"\",nan,6.739379585753305", 3, NULL);
    ROW("0,-2,1e-05,1,0,\"refused: parameters.m0: expected > 0\",nan,nan", 0, NULL);
    ROW("7,1.0000000000000001e+100,-0,0,0,\"theta.settle<6.5: 7 \"\"s\"\"\",inf,-inf", 7, NULL);
    /* the list: a row cut in half, 5 and 3 extra columns, failed=7, run 2^64+1 */
    ROW("3,1.4140917868522627,0.05000", 0, "3 fields where the header has 8");
    ROW("3,1.5,0.05,0,1,\"\",nan,6.7,1,2,3,4,5", 0, "13 fields where the header has 8");
    ROW("3,1.5,0.05,0,1,\"\",nan,6.7,1,2,3", 0, "11 fields where the header has 8");
    ROW("3,1.5,0.05,7,1,\"\",nan,6.7", 0, "field 4 (failed): expected 0 or 1, found '7'");
    ROW("3,1.5,0.05,0,2,\"\",nan,6.7", 0, "field 5 (required): expected 0 or 1, found '2'");
    ROW("18446744073709551617,1.5,0.05,0,1,\"\",nan,6.7", 0,
        "field 1 (run): expected a run number of the sweep (0 to 7), found '18446744073709551617'");
    /* run numbers: in [0, 8), as %ld writes them */
    static const char *const bad_runs[] = {"-1", "8", "+1", "01", "", " 1", "1.0", "1e0",
                                           "18446744073709551615", "9223372036854775808",
                                           "99999999999999999999999999999999"};
    for (size_t i = 0; i < sizeof bad_runs / sizeof *bad_runs; i++) {
        char line[256];
        snprintf(line, sizeof line, "%s,1.5,0.05,0,1,\"\",nan,6.7", bad_runs[i]);
        ROW(line, 0, "field 1 (run): expected a run number of the sweep");
    }
    /* numbers as %.17g writes them; nan only where a metric has no value */
    static const char *const bad_numbers[] = {"nan", "NaN", "0x1p3", ".5", "5.", "1e5", "1e+5",
                                              "1E+05", " 1", "1 ", "", "--1", "in", "infinity",
                                              "\"1\"", "1,5"};
    for (size_t i = 0; i < sizeof bad_numbers / sizeof *bad_numbers; i++) {
        char line[256];
        snprintf(line, sizeof line, "3,%s,0.05,0,1,\"\",nan,6.7", bad_numbers[i]);
        ROW(line, 0, strchr(bad_numbers[i], ',') ? "fields where" : "field 2 (parameters.m0)");
    }
    ROW("3,1.5,0.05,0,1,\"\",nan,NAN", 0, "field 8 (x.settle): expected a number or nan");
    ROW("3,1.5,0.05,0,1,\"\",nan,", 0, "field 8 (x.settle): expected a number or nan, found ''");
    /* the reason: quoted, quotes doubled, closed */
    ROW("3,1.5,0.05,0,1,,nan,6.7", 0, "field 6 (reason): expected the reason in quotes");
    ROW("3,1.5,0.05,0,1,\"a,b\",nan,6.7", 3, NULL);
    ROW("3,1.5,0.05,0,1,\"a\"b\",nan,6.7", 0, "field 6: a quote followed by more than a comma");
    ROW("3,1.5,0.05,0,1,\"open,nan,6.7", 0, "field 6: a quote not closed");
    ROW("3,1\"5,0.05,0,1,\"\",nan,6.7", 0, "field 2: a quote inside a plain field");
    /* control bytes: a NUL (the line's length counts it), a CR, a tab */
    static const char nul[] = "3,1.5,0.05,0,1,\"a\0b\",nan,6.7";
    row(nul, sizeof nul - 1, 0, "a NUL byte at byte 18");
    ROW("3,1.5,0.05,0,1,\"\",nan,6.7\r", 0, "a control byte at byte 26");
    ROW("3,1.5,0.05,0,1,\"a\tb\",nan,6.7", 0, "a control byte at byte 18");
    /* a long row (its reason 1 MB) is checked whole */
    size_t big = 1 << 20;
    char *lng = malloc(big + 64);
    ENSURE(lng != NULL);
    if (!lng) return;
    int u = snprintf(lng, 64, "5,1.5,0.05,0,1,\"");
    memset(lng + u, 'x', big);
    snprintf(lng + u + big, 64, "\",nan,6.7");
    ROW(lng, 5, NULL);
    free(lng);
    sweep_columns_free(&cols);
}

/* The writer's reason, whatever it holds, is one the check takes back. */
static void case_reason(int arg)
{
    (void)arg;
    columns();
    static const char *const reasons[] = {"", "plain", "say \"no\"", "\"", "\"\"", "a,b",
                                          "line\nbreak", "tab\there", "cr\r", "bell\a\x7f",
                                          "utf-8 \xc3\xa9"};
    for (size_t i = 0; i < sizeof reasons / sizeof *reasons; i++) {
        char *buf = NULL;
        size_t len = 0;
        FILE *f = open_memstream(&buf, &len);
        ENSURE(f != NULL);
        if (!f) return;
        fputs("6,1.5,0.05,1,0,", f);
        sweep_write_reason(f, reasons[i]);
        fputs(",nan,nan", f);
        fclose(f);
        row(buf, len, 6, NULL);
        free(buf);
    }
    sweep_columns_free(&cols);
}

static void case_shard(int arg)
{
    (void)arg;
    long k, n;
    static const struct {
        const char *text;
        long k, n;
    } good[] = {{"1/1", 1, 1}, {"1/2", 1, 2}, {"2/2", 2, 2}, {"16/16", 16, 16},
                {"3/10000000", 3, 10000000}};
    for (size_t i = 0; i < sizeof good / sizeof *good; i++)
        ENSUREF(sweep_shard_parse(good[i].text, &k, &n) == 0 && k == good[i].k && n == good[i].n,
                "%s: %ld/%ld", good[i].text, k, n);
    static const char *const bad[] = {"1/2x", "0/2", "3/2", "1/0", " 1/2", "1/ 2", "1 /2",
                                      "1/2 ", "+1/2", "-1/2", "01/2", "1/02", "1/2/3", "1",
                                      "/2", "1/", "/", "", "a/b", "1/10000001",
                                      "18446744073709551617/2", "1/18446744073709551617",
                                      "4294967297/4294967297", "1.0/2", "1e0/2"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        ENSUREF(sweep_shard_parse(bad[i], &k, &n) == -1, "'%s' taken as %ld/%ld", bad[i], k, n);
}

static void case_columns(int arg)
{
    (void)arg;
    char why[256];
    sweep_columns c;
    ENSURE(sweep_columns_parse(HEADER, 2, &c, why, sizeof why) == 0 && c.n == 8 && c.nvary == 2);
    sweep_columns_free(&c);
    static const struct {
        const char *header;
        int nvary;
        const char *fault;
    } bad[] = {
        {HEADER, 1, "no 'failed'"},        /* a vary: line more than the header's keys */
        {HEADER, 3, "no 'failed'"},
        {"runs,a,failed,required,reason,x.iae", 1, "no 'run'"},
        {"run,a,failed,reason,x.iae", 1, "no 'required'"},
        {"run,a,failed,required", 1, "no 'reason'"},
        {"", 0, "no 'run'"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        int rc = sweep_columns_parse(bad[i].header, bad[i].nvary, &c, why, sizeof why);
        ENSUREF(rc == -1 && strstr(why, bad[i].fault), "'%s' with %d: %d '%s'", bad[i].header,
                bad[i].nvary, rc, why);
    }
}

/* path of a new file holding n bytes of data */
static void temp_file(char *path, const char *data, size_t n)
{
    strcpy(path, "/tmp/lagsim-sweep-csv.XXXXXX");
    int fd = mkstemp(path);
    ENSURE(fd >= 0);
    ENSURE(write(fd, data, n) == (ssize_t)n);
    close(fd);
}

/* FIPS 180-2's SHA-256 test vectors (the empty message, "abc", the two-block message). */
static void case_sha256(int arg)
{
    (void)arg;
    static const struct {
        const char *msg, *hex;
    } v[] = {
        {"", "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"},
        {"abc", "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"},
        {"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq",
         "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"},
    };
    for (size_t i = 0; i < sizeof v / sizeof *v; i++) {
        char path[64], hex[65] = "", err[256];
        temp_file(path, v[i].msg, strlen(v[i].msg));
        ENSUREF(sweep_sha256_file(path, hex, err, sizeof err) == 0 && !strcmp(hex, v[i].hex),
                "'%s': %s (%s)", v[i].msg, hex, err);
        unlink(path);
    }
    char hex[65], err[256];
    ENSURE(sweep_sha256_file("/nonexistent/scene.yaml", hex, err, sizeof err) == -1 &&
           strstr(err, "/nonexistent/scene.yaml"));
}

static void case_identity(int arg)
{
    (void)arg;
    char scene[64], err[256];
    temp_file(scene, "abc", 3);
    eval_case c = {.name = "tilt", .duration = 0.1, .nsets = 1, .nbounds = 1,
                   .bound = {0.5}};
    strcpy(c.set[0], "initial.q=[0, 0.1]");
    strcpy(c.bound_joint[0], "theta");
    const char *vary[] = {"parameters.m0=uniform(0.5,2)", "initial.q[1]=normal(0,0.05)"};
    sweep_identity id = {.seed = 9000000000000000ull, .scene = scene, .c = &c, .vary = vary,
                         .nvary = 2, .runs = 12, .controller = "ctl\n-q\t\\x {prefix}\x01",
                         .restart = true, .require = NULL, .shard_k = 2, .shard_n = 3};
    char *text = sweep_identity_text(&id, err, sizeof err);
    ENSUREF(text != NULL, "%s", err);
    if (!text) return;
    const char *want =
        "# lagsim-sweep " LAGSIM_VERSION "\n"
        "# seed: 9000000000000000\n"
        "# scene-sha256: ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad\n"
        "# case: tilt\n"
        "# duration: 0.1\n"
        "# set: initial.q=[0, 0.1]\n"
        "# bound: theta=0.5\n"
        "# vary: parameters.m0=uniform(0.5,2)\n"
        "# vary: initial.q[1]=normal(0,0.05)\n"
        "# runs: 12\n"
        "# controller: ctl\\n-q\\t\\\\x {prefix}\\x01\n"
        "# restart: yes\n"
        "# shard: 2/3\n";
    ENSUREF(!strcmp(text, want), "\n%s\nexpected\n%s", text, want);
    free(text);
    /* the whole sweep: no shard line; --require's line */
    id.shard_k = id.shard_n = 1, id.require = "theta.settle<7", id.restart = false;
    text = sweep_identity_text(&id, err, sizeof err);
    ENSURE(text && !strstr(text, "# shard:") && strstr(text, "\n# restart: no\n") &&
           strstr(text, "\n# require: theta.settle<7\n"));
    free(text);
    unlink(scene);
    id.scene = scene; /* gone: said */
    ENSURE(sweep_identity_text(&id, err, sizeof err) == NULL && strstr(err, scene));
}

/* 300 shards of a sweep of 300 runs, one run each, written as lagsim-sweep writes them:
 * merged, every one of them (merge once kept the first 256 inputs), the output the whole
 * sweep's CSV. */
static void case_merge_many(int arg)
{
    (void)arg;
    enum { N = 300 };
    char dir[] = "/tmp/lagsim-sweep-many.XXXXXX", scene[64], err[256];
    ENSURE(mkdtemp(dir) != NULL);
    temp_file(scene, "abc", 3);
    eval_case c = {.name = "sweep", .duration = 1};
    const char *vary[] = {"a=uniform(1,2)"};
    sweep_identity id = {.seed = 1, .scene = scene, .c = &c, .vary = vary, .nvary = 1,
                         .runs = N, .controller = "ctl", .shard_n = N};
    static char path[N][96];
    char *argv[N + 3];
    argv[0] = "merge";
    for (int k = 0; k < N; k++) {
        id.shard_k = k + 1;
        char *text = sweep_identity_text(&id, err, sizeof err);
        snprintf(path[k], sizeof path[k], "%s/shard-%d.csv", dir, k + 1);
        FILE *f = fopen(path[k], "w");
        ENSURE(text && f);
        if (!text || !f) return;
        fprintf(f, "%srun,a,failed,required,reason,x.iae\n%d,1.5,0,1,\"\",nan\n", text, k);
        fclose(f);
        free(text);
        argv[1 + k] = path[k];
    }
    char out[96];
    snprintf(out, sizeof out, "%s/merged.csv", dir);
    argv[N + 1] = "-o", argv[N + 2] = out;
    ENSURE(merge(N + 3, argv, NULL) == 0);
    /* the whole sweep's CSV: the identity of shard 1/1, the header, the 300 rows */
    id.shard_k = id.shard_n = 1;
    char *want = NULL, *text = sweep_identity_text(&id, err, sizeof err);
    size_t wlen = 0;
    FILE *w = open_memstream(&want, &wlen);
    fprintf(w, "%srun,a,failed,required,reason,x.iae\n", text);
    for (int k = 0; k < N; k++) fprintf(w, "%d,1.5,0,1,\"\",nan\n", k);
    fclose(w);
    char got[65536] = "";
    FILE *f = fopen(out, "r");
    size_t n = f ? fread(got, 1, sizeof got - 1, f) : 0;
    if (f) fclose(f);
    ENSUREF(n == wlen && !memcmp(got, want, wlen), "merged (%zu bytes):\n%.400s", n, got);
    free(want), free(text);
    for (int k = 0; k < N; k++) unlink(path[k]);
    unlink(out), unlink(scene), rmdir(dir);
}

/* A held line's runs: what the text names, what the writer writes back (ranges counted in
 * the shards' runs), the texts that are none of that. */
static void case_runs(int arg)
{
    (void)arg;
    unsigned char set[20], all[1] = {1}, second[2] = {0, 1};
    ENSURE(sweep_runs_parse("0-3,5,7-8", 20, set) == 0);
    for (int r = 0; r < 20; r++)
        ENSUREF(set[r] == (r <= 3 || r == 5 || r == 7 || r == 8), "run %d: %d", r, set[r]);
    char *t = sweep_runs_text(set, 20, 1, all);
    ENSUREF(t && !strcmp(t, "0-3,5,7-8"), "written back as '%s'", t ? t : "(null)");
    free(t);
    /* shard 2/2's runs 1, 3, 5, 9 of 20: "1-5,9" (7 is the shard's, not held) */
    memset(set, 0, sizeof set);
    set[1] = set[3] = set[5] = set[9] = 1;
    set[4] = 1; /* shard 1/2's: not written under shard 2/2 */
    t = sweep_runs_text(set, 20, 2, second);
    ENSUREF(t && !strcmp(t, "1-5,9"), "shard 2/2: '%s'", t ? t : "(null)");
    free(t);
    memset(set, 0, sizeof set);
    t = sweep_runs_text(set, 20, 1, all);
    ENSUREF(t && !strcmp(t, "none"), "no run: '%s'", t ? t : "(null)");
    free(t);
    ENSURE(sweep_runs_parse("none", 20, set) == 0 && !memchr(set, 1, sizeof set));
    ENSURE(sweep_runs_parse("19", 20, set) == 0 && set[19] == 1);
    static const char *const bad[] = {"", "3-1", "1,1", "2,1", "0-20", "20", "-1", "01",
                                      "1-", "1,", ",1", "1 ,2", "a", "1-2-3", "0x3",
                                      "18446744073709551617", "unknown"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        ENSUREF(sweep_runs_parse(bad[i], 20, set) == -1, "'%s' taken", bad[i]);
}

/* --require's reason (eval_require_holds, lagsim-eval's and lagsim-sweep's): every term that
 * fails with its value, none that holds; cut short at the caller's buffer with how many
 * more fail, never past it. */
static void case_require(int arg)
{
    (void)arg;
    eval_scene sc = {.model = "cartpole", .nj = 2, .joint = {"x", "theta"}};
    eval_result res = {.nj = 2};
    for (int j = 0; j < 2; j++)
        for (int m = 0; m < LAG_METRIC_COUNT; m++) res.m[j].v[m] = 1.0;
    res.m[1].v[LAG_METRIC_SETTLE] = 5.5;
    res.m[0].v[LAG_METRIC_SETTLE] = NAN;
    lag_require req;
    char err[256], why[2048];
    ENSUREF(lag_require_parse("theta.settle < 2 and theta.rise < 3 and x.settle < 3", &req, err,
                              sizeof err) == 0, "%s", err);
    ENSURE(!eval_require_holds(&req, &sc, &res, why, sizeof why));
    ENSUREF(!strcmp(why, "theta.settle < 2 fails (5.5); x.settle < 3 fails (nan)"), "%s", why);
    ENSURE(lag_require_parse("theta.rise < 3", &req, err, sizeof err) == 0);
    ENSURE(eval_require_holds(&req, &sc, &res, why, sizeof why) && why[0] == '\0');
    /* 32 terms that fail in 300 bytes: those that fit, then the count of the rest */
    char text[2048] = "";
    for (int i = 0; i < LAG_REQUIRE_MAX; i++)
        snprintf(text + strlen(text), sizeof text - strlen(text), "%stheta.settle > %d",
                 i ? " and " : "", 10 + i);
    ENSUREF(lag_require_parse(text, &req, err, sizeof err) == 0 && req.n == 32, "%s", err);
    char small[300];
    memset(small, 'X', sizeof small);
    ENSURE(!eval_require_holds(&req, &sc, &res, small, 280));
    int said = 0;
    for (const char *p = small; (p = strstr(p, " fails (5.5)")) != NULL; p++) said++;
    char tail[64];
    snprintf(tail, sizeof tail, "; and %d more terms fail", 32 - said);
    ENSUREF(said >= 5 && strlen(small) < 280 && strstr(small, tail) &&
            !strcmp(small + strlen(small) - strlen(tail), tail) && small[299] == 'X',
            "%d said: %s", said, small);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {
        {"require", case_require, 0, 0},
        {"rows", case_rows, 0, 0},         {"reason", case_reason, 0, 0},
        {"shard", case_shard, 0, 0},       {"columns", case_columns, 0, 0},
        {"sha256", case_sha256, 0, 0},     {"identity", case_identity, 0, 0},
        {"merge_many", case_merge_many, 0, 0}, {"runs", case_runs, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
