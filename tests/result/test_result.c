/*
 * The one result-code space (lagsim/result.h): every code has a name, a sentence and an
 * exit status from the one table, the loader's and the client's codes are codes of it, the
 * programs' exit statuses are the ones their docs give.
 *
 *   test_result             runs the cases
 *   test_result --table     prints the table, "NAME VALUE EXIT" a line (exit_docs.py reads it)
 */
#include "lagsim_test.h"

#include "daemon.h"
#include "lagsim/result.h"
#include "lagsim_client.h"
#include "scene.h"

/* The table as the header lists it, read here row by row. */
typedef struct row {
    lag_result code;
    const char *name;
    int exit_status;
    const char *text;
} row;
#define ROW_(code, value, exit_status, text) {code, #code, exit_status, text},
static const row table[] = {LAG_RESULT_LIST(ROW_)};
#undef ROW_
enum { NROWS = (int)(sizeof table / sizeof table[0]) };

/* The client's names keep the values they always had: a controller built against an
 * older lagsim_client.h, or testing rc < 0 for an error, keeps working. */
_Static_assert(LAG_CLIENT_OK == 0 && LAG_CLIENT_TIMEOUT == 2 && LAG_CLIENT_ERR_ARG == -1 &&
                   LAG_CLIENT_ERR_LCM == -2 && LAG_CLIENT_ERR_NOMEM == -3 &&
                   LAG_CLIENT_ERR_AMBIGUOUS == -4,
               "the client's result codes keep their values");

/* Each row: its name and sentence from lag_result_name / lag_result_string, its exit
 * status from lag_result_exit and one the programs document (0..3); errors negative,
 * the rest (LAG_OK, LAG_TIMEOUT) not; no value twice. */
static void case_table(int arg)
{
    (void)arg;
    ENSURE(NROWS >= 20);
    for (int i = 0; i < NROWS; i++) {
        const row *r = &table[i];
        const char *name = lag_result_name(r->code);
        if (!name || strcmp(name, r->name) != 0)
            LT_FAIL("code %d: lag_result_name gives %s, the table %s", (int)r->code,
                    name ? name : "NULL", r->name);
        ENSURE(strcmp(lag_result_string(r->code), r->text) == 0);
        ENSURE(r->text[0] != '\0');
        ENSURE(lag_result_exit(r->code) == r->exit_status);
        ENSURE(r->exit_status >= 0 && r->exit_status <= 3);
        const bool is_error = strncmp(r->name, "LAG_ERR_", 8) == 0;
        if (is_error != (r->code < 0))
            LT_FAIL("%s = %d: errors are negative, other results not", r->name, (int)r->code);
        if (is_error && r->exit_status == 0)
            LT_FAIL("%s: an error that exits 0", r->name);
        for (int j = 0; j < i; j++)
            if (table[j].code == r->code)
                LT_FAIL("%s and %s share the value %d", table[j].name, r->name, (int)r->code);
    }
    /* a value that is no code: no name, exit 1, a sentence that says so */
    const int not_codes[] = {1, 3, 1000, -1000, INT32_MIN};
    for (int k = 0; k < (int)(sizeof not_codes / sizeof not_codes[0]); k++) {
        lag_result v = (lag_result)not_codes[k];
        ENSURE(lag_result_name(v) == NULL);
        ENSURE(lag_result_exit(v) == 1);
        ENSURE(strcmp(lag_result_string(v), "unknown result") == 0);
    }
}

/* The exit statuses the man pages give (tests/result/exit_docs.py checks the pages and
 * the programs against the table; this pins the table's side). */
static void case_exit_statuses(int arg)
{
    (void)arg;
    ENSURE(lag_result_exit(LAG_OK) == 0);
    ENSURE(lag_result_exit(LAG_ERR_USAGE) == 2);
    ENSURE(lag_result_exit(LAG_ERR_SCENE) == 2);
    ENSURE(lag_result_exit(LAG_ERR_FILE) == 2);
    ENSURE(lag_result_exit(LAG_ERR_AMBIGUOUS) == 2);
    ENSURE(lag_result_exit(LAG_ERR_RUNTIME) == 1);
    ENSURE(lag_result_exit(LAG_ERR_MISMATCH) == 1);
    ENSURE(lag_result_exit(LAG_ERR_REFUSED) == 1);
    ENSURE(lag_result_exit(LAG_ERR_NOANSWER) == 3);
    /* lagsimd: 0 ok, 1 runtime failure, 2 usage or scene error */
    ENSURE(lag_result_exit(LAGSIMD_EXIT_OK) == 0);
    ENSURE(lag_result_exit(LAGSIMD_EXIT_RUNTIME) == 1);
    ENSURE(lag_result_exit(LAGSIMD_EXIT_USAGE) == 2);
    /* a numeric fault ends a run with 1 */
    const lag_result faults[] = {LAG_ERR_SINGULAR, LAG_ERR_NONFINITE, LAG_ERR_EXPLODE,
                                 LAG_ERR_NEWTON,   LAG_ERR_STEPSIZE,  LAG_ERR_LIFTOFF,
                                 LAG_ERR_FORCE,    LAG_ERR_MAX_STEPS};
    for (int k = 0; k < (int)(sizeof faults / sizeof faults[0]); k++)
        ENSURE(lag_result_exit(faults[k]) == 1);
}

/* The loader answers with codes of the space: a plain decimal, one that is not, one too
 * large; a URL refused; a scene refused; a file that is not there. */
static void case_loader(int arg)
{
    (void)arg;
    double v = 0.0;
    char err[512];
    int ttl = 0;
    lag_scene sc;
    ENSURE(lag_scene_read_decimal("1.5e3", &v) == LAG_OK && v == 1500.0);
    ENSURE(lag_scene_read_decimal("0x10", &v) == LAG_ERR_SYNTAX);
    ENSURE(lag_scene_read_decimal("1e999", &v) == LAG_ERR_RANGE);
    ENSURE(lag_scene_check_url("memq://", false, &ttl, err, sizeof err) == LAG_OK);
    ENSURE(lag_scene_check_url("file:///tmp/x", false, &ttl, err, sizeof err) == LAG_ERR_SCENE);
    const char bad[] = "model: nosuchmodel\n";
    ENSURE(lag_scene_load_buffer("t.yaml", bad, sizeof bad - 1, NULL, 0, &sc, err, sizeof err) ==
           LAG_ERR_SCENE);
    const char good[] = "model: dipc\n";
    ENSURE(lag_scene_load_buffer("t.yaml", good, sizeof good - 1, NULL, 0, &sc, err,
                                 sizeof err) == LAG_OK);
    char *text = NULL;
    size_t len = 0;
    ENSURE(lag_scene_read("/nonexistent/scene.yaml", &text, &len, err, sizeof err) ==
           LAG_ERR_SCENE);
    ENSURE(lag_scene_load(NULL, NULL, 0, &sc, err, sizeof err) == LAG_ERR_ARG);
    /* every one of them ends a program with 2: nothing ran */
    ENSURE(lag_result_exit(LAG_ERR_SYNTAX) == 2 && lag_result_exit(LAG_ERR_RANGE) == 2);
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--table") == 0) {
        for (int i = 0; i < NROWS; i++)
            printf("%s %d %d\n", table[i].name, (int)table[i].code, table[i].exit_status);
        return 0;
    }
    static const lt_case cases[] = {
        {"table", case_table, 0, 0},
        {"exit_statuses", case_exit_statuses, 0, 0},
        {"loader", case_loader, 0, 0},
    };
    return lt_main(argc, argv, cases, (int)(sizeof cases / sizeof cases[0]));
}
