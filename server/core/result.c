/*
 * The result-code table (lagsim/result.h): name, sentence and exit status of each code,
 * all from LAG_RESULT_LIST.
 */
#include <stddef.h>

#include "lagsim/result.h"

typedef struct result_row {
    lag_result code;
    const char *name;
    const char *text;
    int exit_status;
} result_row;

#define RESULT_ROW_(code, value, exit_status, text) {code, #code, text, exit_status},
static const result_row rows[] = {LAG_RESULT_LIST(RESULT_ROW_)};
#undef RESULT_ROW_

/* Every exit status in the table is one the programs document (0..3). */
#define RESULT_EXIT_OK_(code, value, exit_status, text) \
    _Static_assert((exit_status) >= 0 && (exit_status) <= 3, #code ": exit status 0..3");
LAG_RESULT_LIST(RESULT_EXIT_OK_)
#undef RESULT_EXIT_OK_

/* Row index of each code. */
#define RESULT_INDEX_(code, value, exit_status, text) ROW_##code,
enum { LAG_RESULT_LIST(RESULT_INDEX_) ROW_COUNT };
#undef RESULT_INDEX_
_Static_assert(sizeof rows / sizeof rows[0] == ROW_COUNT, "one row per code");

/* A switch, so that two codes with one value do not compile (duplicate case value). */
static const result_row *row_of(lag_result r)
{
#define RESULT_CASE_(code, value, exit_status, text) \
    case code:                                      \
        return &rows[ROW_##code];
    switch (r) {
        LAG_RESULT_LIST(RESULT_CASE_)
    }
#undef RESULT_CASE_
    return NULL;
}

const char *lag_result_name(lag_result r)
{
    const result_row *w = row_of(r);
    return w ? w->name : NULL;
}

const char *lag_result_string(lag_result r)
{
    const result_row *w = row_of(r);
    return w ? w->text : "unknown result";
}

int lag_result_exit(lag_result r)
{
    const result_row *w = row_of(r);
    return w ? w->exit_status : 1;
}
