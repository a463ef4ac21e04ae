/*
 * lagsim_lists: the generated parts of the committed docs, man pages, message comments and
 * scenes (lists.h says which and how they are marked).
 *
 *   lagsim_lists check SOURCE BUILD     every committed block as the tables give it, else
 *                                       exit 1 naming each stale block and the command
 *                                       that rewrites them (ctest structure_lists)
 *   lagsim_lists write SOURCE           rewrite the stale blocks in place (the build's
 *                                       target `lists`; nothing else writes the sources)
 *   lagsim_lists splice SOURCE IN OUT   IN with its blocks generated, to OUT (the man
 *                                       pages the build installs)
 *   lagsim_lists print SOURCE BLOCK     one block, as generated
 *   lagsim_lists blocks                 the blocks this program writes
 *
 * Exit status: 0 done (check: every block current), 1 stale blocks (check) or a file that
 * cannot be read or written, 2 usage, an unknown block or a marker without its end.
 */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lists.h"

/* How one file is spliced: its name for messages, whether stale blocks are said. */
typedef struct splice_job {
    const char *label;
    bool report;
    int stale;  /* blocks whose committed text differs */
    int failed; /* unknown blocks, open markers, generators that failed */
    lists_ctx *cx;
} splice_job;

static int line_of(const char *text, const char *at)
{
    int line = 1;
    for (const char *p = text; p < at; p++) line += *p == '\n';
    return line;
}

/* Says where the committed text first differs from the generated one. */
static void say_stale(splice_job *j, int line, const char *name, const char *old, size_t oldn,
                      const lbuf *want)
{
    size_t i = 0;
    while (i < oldn && i < want->n && old[i] == want->s[i]) i++;
    size_t a = i, b = i;
    while (a > 0 && old[a - 1] != '\n') a--;
    while (b < want->n && want->s[b] != '\n') b++;
    size_t e = a;
    while (e < oldn && old[e] != '\n') e++;
    j->stale++;
    if (!j->report) return;
    printf("%s:%d: block '%s' is not what the tables give\n  has:  %.*s\n  want: %.*s\n", j->label,
           line, name, (int)(e - a), old + a, (int)(b - a), want->s + a);
}

static void say_error(splice_job *j, const char *text, const char *at, const char *msg,
                      const char *name, size_t len)
{
    j->failed++;
    fprintf(stderr, "%s:%d: %s '%.*s'%s%s\n", j->label, line_of(text, at), msg, (int)len, name,
            j->cx->err[0] ? ": " : "", j->cx->err);
    j->cx->err[0] = '\0';
}

/* The block `name` (len bytes) generated into want; false after saying why. */
static bool generate(splice_job *j, const char *text, const char *at, const char *name, size_t len,
                     bool lines, lbuf *want)
{
    const lists_block *blk = lists_block_find(name, len);
    if (!blk) {
        say_error(j, text, at, "unknown block (lagsim_lists blocks lists them)", name, len);
        return false;
    }
    if (blk->lines != lines) {
        say_error(j, text, at, blk->lines ? "a table's block needs its markers on lines of their own"
                                          : "an inline block, marked as lines", name, len);
        return false;
    }
    if (!blk->gen(want, j->cx)) {
        say_error(j, text, at, "cannot generate block", name, len);
        return false;
    }
    return true;
}

/* How a format marks a block: "<!-- lists:NAME -->" ... "<!-- /lists:NAME -->" in
 * Markdown, ".\" lists:NAME" ... ".\" /lists:NAME" on lines of their own in troff. */
typedef struct marker {
    const char *open, *close, *after;
    bool lines; /* the block is always the lines between the markers */
} marker;
static const marker k_markdown = {"<!-- lists:", "<!-- /lists:", " -->", false};
static const marker k_troff = {".\\\" lists:", ".\\\" /lists:", "\n", true};

/* The block marked at `at`: appends it as generated (as it was, after an error) to out;
 * returns where the text goes on. */
static const char *marked(splice_job *j, const char *text, const char *at, const marker *m, lbuf *out)
{
    const char *name = at + strlen(m->open);
    size_t len = strspn(name, "abcdefghijklmnopqrstuvwxyz0123456789-");
    char end[128];
    snprintf(end, sizeof end, "%s%.*s%s", m->close, (int)(len < 60 ? len : 60), name, m->after);
    const char *body = strncmp(name + len, m->after, strlen(m->after)) == 0 && len > 0 && len < 60
                           ? name + len + strlen(m->after) : NULL;
    const char *stop = body ? strstr(body, end) : NULL;
    if (len == 0) { /* "lists:NAME" in a text that tells of the markers: not one */
        lb_putn(out, at, strlen(m->open));
        return at + strlen(m->open);
    }
    if (!stop || (m->lines && stop[-1] != '\n')) {
        say_error(j, text, at, "a marker without its end (or its name) for block", name, len);
        lb_putn(out, at, strlen(m->open));
        return at + strlen(m->open);
    }
    bool lines = m->lines || body[0] == '\n';
    lbuf want = {0};
    if (lines && !m->lines) lb_put(&want, "\n");
    char bname[64];
    snprintf(bname, sizeof bname, "%.*s", (int)len, name);
    lb_putn(out, at, (size_t)(body - at));
    if (generate(j, text, at, name, len, lines, &want)) {
        if ((size_t)(stop - body) != want.n || memcmp(body, want.s, want.n) != 0)
            say_stale(j, line_of(text, at), bname, body, (size_t)(stop - body), &want);
        lb_putn(out, want.s, want.n);
    } else {
        lb_putn(out, body, (size_t)(stop - body));
    }
    lb_free(&want);
    return stop;
}

/* A comment's "lagsimd --list WHAT: ..." at `at`: the rest of the line is the list. Only
 * in a comment (a # or // before it on its line); elsewhere the words are text. */
static const char *tail(splice_job *j, const char *text, const char *at, lbuf *out)
{
    static const char lead[] = "lagsimd --list ";
    const char *what = at + strlen(lead), *bol = at;
    size_t len = strspn(what, "abcdefghijklmnopqrstuvwxyz");
    while (bol > text && bol[-1] != '\n') bol--;
    char line[1024];
    snprintf(line, sizeof line, "%.*s", (int)(at - bol), bol);
    bool comment = strchr(line, '#') || strstr(line, "//");
    if (!comment || len == 0 || strncmp(what + len, ": ", 2) != 0) {
        lb_putn(out, at, strlen(lead));
        return at + strlen(lead);
    }
    const char *body = what + len + 2, *eol = body + strcspn(body, "\n");
    lbuf want = {0};
    lb_putn(out, at, (size_t)(body - at));
    if (!lists_tail(&want, what, len)) {
        say_error(j, text, at, "lagsimd --list knows no list", what, len);
        lb_putn(out, body, (size_t)(eol - body));
    } else {
        if ((size_t)(eol - body) != want.n || memcmp(body, want.s, want.n) != 0) {
            char name[64];
            snprintf(name, sizeof name, "lagsimd --list %.*s", (int)len, what);
            say_stale(j, line_of(text, at), name, body, (size_t)(eol - body), &want);
        }
        lb_putn(out, want.s, want.n);
    }
    lb_free(&want);
    return eol;
}

/* A man page's title line, `.TH NAME 1 DATE "lagsim VERSION" ...`: the version is the
 * project's (CMakeLists.txt), so that a new version is one line there. */
static const char *title_line(splice_job *j, const char *text, const char *at, lbuf *out)
{
    const char *eol = at + strcspn(at, "\n"), *v = strstr(at, "\"lagsim ");
    if (!v || v > eol) {
        lb_putn(out, at, (size_t)(eol - at));
        return eol;
    }
    v += strlen("\"lagsim ");
    const char *end = v + strcspn(v, "\"\n");
    lbuf want = {0};
    lb_put(&want, LAGSIM_VERSION);
    if ((size_t)(end - v) != want.n || memcmp(v, want.s, want.n) != 0)
        say_stale(j, line_of(text, at), "the version (CMakeLists.txt)", v, (size_t)(end - v), &want);
    lb_putn(out, at, (size_t)(v - at));
    lb_putn(out, want.s, want.n);
    lb_free(&want);
    return end;
}

/* The first of `pat` at or after p that starts a line; NULL if none. */
static const char *at_line_start(const char *text, const char *p, const char *pat)
{
    const char *q = strstr(p, pat);
    while (q && q > text && q[-1] != '\n') q = strstr(q + 1, pat);
    return q;
}

/* text with every block generated, into out. */
static void splice(splice_job *j, const char *text, lbuf *out)
{
    const char *p = text;
    for (;;) {
        const char *md = strstr(p, k_markdown.open), *tr = at_line_start(text, p, k_troff.open);
        const char *tl = strstr(p, "lagsimd --list "), *th = at_line_start(text, p, ".TH ");
        const char *at = md;
        if (!at || (tr && tr < at)) at = tr;
        if (!at || (tl && tl < at)) at = tl;
        if (!at || (th && th < at)) at = th;
        if (!at) break;
        lb_putn(out, p, (size_t)(at - p));
        if (at == md) p = marked(j, text, at, &k_markdown, out);
        else if (at == tr) p = marked(j, text, at, &k_troff, out);
        else if (at == th) p = title_line(j, text, at, out);
        else p = tail(j, text, at, out);
    }
    lb_put(out, p);
}

/* ---------------------------------------------------------------- files */

static bool read_all(const char *path, lbuf *b)
{
    FILE *f = fopen(path, "rb");
    if (!f) return false;
    char chunk[65536];
    size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0) lb_putn(b, chunk, n);
    bool ok = !ferror(f);
    fclose(f);
    if (!b->s) lb_put(b, "");
    return ok;
}

static bool write_all(const char *path, const lbuf *b)
{
    FILE *f = fopen(path, "wb");
    if (!f) return false;
    bool ok = fwrite(b->s, 1, b->n, f) == b->n;
    return fclose(f) == 0 && ok;
}

/* Splices one file (`rel` under the source tree, or a path): returns 0, 1 (stale, in
 * check mode) or 2 (an error). write: rewrite it if its blocks are stale. */
static int one_file(lists_ctx *cx, const char *path, const char *label, bool write, bool report)
{
    lbuf text = {0}, out = {0};
    if (!read_all(path, &text)) {
        fprintf(stderr, "lagsim_lists: cannot read %s\n", path);
        return 1;
    }
    splice_job j = {.label = label, .report = report, .cx = cx};
    splice(&j, text.s, &out);
    int rc = j.failed ? 2 : j.stale && !write ? 1 : 0;
    if (!j.failed && j.stale && write) {
        if (!write_all(path, &out)) {
            fprintf(stderr, "lagsim_lists: cannot write %s\n", path);
            rc = 1;
        } else {
            printf("lagsim_lists: %s: %d block%s rewritten\n", label, j.stale, j.stale == 1 ? "" : "s");
        }
    }
    lb_free(&text);
    lb_free(&out);
    return rc;
}

/* The committed files that may hold blocks (README.md, and in docs, docs/man, lcmtypes
 * and config those ending .md, .1, .lcm, .yaml), each spliced; the worst result. */
static int each_file(lists_ctx *cx, bool write, bool report)
{
    static const struct { const char *dir, *ext; } where[] = {
        {".", "README.md"}, {"docs", ".md"}, {"docs/man", ".1"}, {"lcmtypes", ".lcm"}, {"config", ".yaml"},
    };
    int worst = 0;
    for (size_t w = 0; w < sizeof where / sizeof where[0]; w++) {
        char dir[1024];
        snprintf(dir, sizeof dir, "%s/%s", cx->source, where[w].dir);
        DIR *d = opendir(dir);
        if (!d) {
            fprintf(stderr, "lagsim_lists: cannot read %s\n", dir);
            return 1;
        }
        for (struct dirent *e; (e = readdir(d)) != NULL;) {
            size_t n = strlen(e->d_name), x = strlen(where[w].ext);
            if (e->d_name[0] == '.' || n < x || strcmp(e->d_name + n - x, where[w].ext) != 0) continue;
            char path[2048], rel[1024];
            snprintf(rel, sizeof rel, "%s%s%s", strcmp(where[w].dir, ".") ? where[w].dir : "",
                     strcmp(where[w].dir, ".") ? "/" : "", e->d_name);
            snprintf(path, sizeof path, "%s/%s", cx->source, rel);
            int rc = one_file(cx, path, rel, write, report);
            if (rc > worst) worst = rc;
        }
        closedir(d);
    }
    return worst;
}

/* ---------------------------------------------------------------- main */

static int usage(void)
{
    fputs("usage: lagsim_lists check SOURCE BUILD | write SOURCE | splice SOURCE IN OUT |\n"
          "                    print SOURCE BLOCK | blocks\n"
          "The lists of models, integrators, effects and channels in the docs, man pages,\n"
          "message comments and scenes, generated from the core's tables (server/lists/lists.h).\n",
          stderr);
    return 2;
}

static int cmd_splice(lists_ctx *cx, const char *in, const char *outpath)
{
    lbuf text = {0}, out = {0};
    if (!read_all(in, &text)) {
        fprintf(stderr, "lagsim_lists: cannot read %s\n", in);
        return 1;
    }
    splice_job j = {.label = in, .report = false, .cx = cx};
    splice(&j, text.s, &out);
    int rc = j.failed ? 2 : 0;
    if (!rc && !write_all(outpath, &out)) {
        fprintf(stderr, "lagsim_lists: cannot write %s\n", outpath);
        rc = 1;
    }
    lb_free(&text);
    lb_free(&out);
    return rc;
}

static int cmd_print(lists_ctx *cx, const char *name)
{
    const lists_block *b = lists_block_find(name, strlen(name));
    lbuf out = {0};
    if (!b && !lists_tail(&out, name, strlen(name))) {
        fprintf(stderr, "lagsim_lists: unknown block '%s' (lagsim_lists blocks)\n", name);
        return 2;
    }
    if (b && !b->gen(&out, cx)) {
        fprintf(stderr, "lagsim_lists: block '%s': %s\n", name, cx->err);
        return 1;
    }
    printf("%s%s", out.s ? out.s : "", b && b->lines ? "" : "\n");
    lb_free(&out);
    return 0;
}

int main(int argc, char **argv)
{
    lists_ctx cx = {.source = argc > 2 ? argv[2] : "."};
    const char *cmd = argc > 1 ? argv[1] : "";
    if (!strcmp(cmd, "blocks") && argc == 2) {
        for (int i = 0; i < lists_block_count; i++)
            printf("%-17s %s\n", lists_blocks[i].name, lists_blocks[i].what);
        puts("(and, in a comment, \"lagsimd --list models|methods|effects: ...\")");
        return 0;
    }
    if (!strcmp(cmd, "check") && argc == 4) {
        int rc = each_file(&cx, false, true);
        if (rc == 1)
            printf("stale generated blocks: rewrite them with\n  cmake --build %s --target lists\n", argv[3]);
        return rc;
    }
    if (!strcmp(cmd, "write") && argc == 3) return each_file(&cx, true, false);
    if (!strcmp(cmd, "splice") && argc == 5) return cmd_splice(&cx, argv[3], argv[4]);
    if (!strcmp(cmd, "print") && argc == 4) return cmd_print(&cx, argv[3]);
    return usage();
}
