/*
 * lagsim_lists: every list of models, integrators, effects and channels written outside
 * the core's tables is generated from them (the model, method and effect tables, the
 * models' lag_model_doc, the bus's channel table and the shipped scenes in config/).
 *
 * A generated part of a committed file sits between markers that name its block:
 *
 *   Markdown   <!-- lists:NAME -->...<!-- /lists:NAME -->   (inline, or a table on the
 *                                                             lines between them)
 *   troff      .\" lists:NAME  ...lines...  .\" /lists:NAME
 *   a comment  "lagsimd --list WHAT: a | b | c" to the end of the line, after # or //
 *              (WHAT: models, methods or effects): a YAML scene's or an .lcm file's
 *              comment names the list and the command that prints it
 *   a man page's title line .TH ... "lagsim VERSION": the project's version
 *
 * The build writes the man pages it installs through the same blocks (splice), so an
 * installed page is never stale; the committed files are rewritten only on request
 * (`cmake --build build --target lists`), and the ctest structure_lists fails, saying that
 * command, when a committed block differs from what the tables give.
 */
#ifndef LAGSIM_LISTS_H
#define LAGSIM_LISTS_H

#include <stdbool.h>
#include <stddef.h>

/* A growing string (the generator allocates; it is a build tool, not the core). */
typedef struct lbuf {
    char *s;
    size_t n, cap;
} lbuf;

void lb_put(lbuf *b, const char *text);
void lb_putn(lbuf *b, const char *text, size_t n);
void lb_printf(lbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void lb_free(lbuf *b);

/* What a block's generator may read besides the core's tables (and the bus's channels,
 * the reference library's kinds): the source tree (config/). */
typedef struct lists_ctx {
    const char *source; /* the source tree's root */
    char err[512];      /* why a generator failed */
} lists_ctx;

/* One generated block: its name in the markers, whether it is a table written on the
 * lines between its markers (else inline text), and its generator (false: failed, the
 * reason in cx->err). */
typedef struct lists_block {
    const char *name;
    bool lines;
    bool (*gen)(lbuf *out, lists_ctx *cx);
    const char *what; /* for `lagsim_lists blocks` */
} lists_block;

extern const lists_block lists_blocks[];
extern const int lists_block_count;
const lists_block *lists_block_find(const char *name, size_t len);

/* The list a comment's "lagsimd --list WHAT:" ends with: "a | b | c"; false when WHAT is
 * not one lagsimd --list knows (models, methods, effects). */
bool lists_tail(lbuf *out, const char *what, size_t len);

#endif
