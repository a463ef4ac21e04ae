/*
 * lagsim's one reader of LCM URLs: see lagsim_url.h. A reader walks the URL in named
 * steps (provider, group, port, end of the address, options), each of which says what it
 * expected when the URL is not what it reads.
 */
#include "lagsim_url.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

typedef struct url_reader {
    const char *url; /* the whole URL, for messages */
    const char *p;   /* the next character to read */
    int flags;
    lag_url *u;
    char *err;
    size_t errlen;
} url_reader;

__attribute__((format(printf, 2, 3))) static bool fail(url_reader *r, const char *fmt, ...)
{
    if (r->err && r->errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(r->err, r->errlen, fmt, ap);
        va_end(ap);
    }
    return false;
}

/* Reads 1 to maxdigits decimal digits at *p into *v, without leading zeros; advances *p
 * only on success. */
static bool read_uint(const char **p, int maxdigits, long *v)
{
    const char *s = *p;
    long x = 0;
    int n = 0;
    while (*s >= '0' && *s <= '9' && n < maxdigits) {
        x = 10 * x + (*s++ - '0');
        n++;
    }
    if (n == 0 || (*s >= '0' && *s <= '9') || (n > 1 && **p == '0')) return false;
    *p = s;
    *v = x;
    return true;
}

/* memq:// (nothing after it) or udpm://; leaves p after "udpm://". */
static bool read_provider(url_reader *r)
{
    const char *url = r->url;
    if (strncmp(url, "memq://", 7) == 0) {
        r->u->provider = LAG_URL_MEMQ;
        if (url[7] != '\0') return fail(r, "memq:// takes no address or options, got '%s'", url);
        r->p = url + 7;
        return true;
    }
    if (strncmp(url, "udpm://", 7) == 0) {
        r->u->provider = LAG_URL_UDPM;
        r->p = url + 7;
        return true;
    }
    const char *sep = strstr(url, "://");
    int n = sep ? (int)(sep - url) : 0;
    bool scene = r->flags & LAG_URL_SCENE_RULES;
    if (sep && n < 16)
        return fail(r, "LCM provider '%.*s://' is not accepted %s: expected "
                    "udpm://GROUP:PORT?ttl=0 (or memq:// %s)", n, url,
                    scene ? "in a scene" : "by a lagsim plant", scene ? "for tests" : "in one process");
    return fail(r, "expected an LCM URL udpm://GROUP:PORT?ttl=0 (or memq:// %s), got '%s'",
                scene ? "for tests" : "in one process", url);
}

/* GROUP: four decimal octets, a multicast address; LCM's default when absent. */
static bool read_group(url_reader *r)
{
    lag_url *u = r->u;
    if (*r->p == '\0' || *r->p == '?') {
        snprintf(u->group, sizeof u->group, "%s", LAG_URL_DEFAULT_GROUP);
        return true;
    }
    long oct[4];
    for (int i = 0; i < 4; i++)
        if ((i > 0 && *r->p++ != '.') || !read_uint(&r->p, 3, &oct[i]) || oct[i] > 255)
            return fail(r, "expected udpm://GROUP:PORT with GROUP a dotted IPv4 multicast "
                        "address (e.g. 239.255.76.67), got '%s'", r->url);
    if (oct[0] < 224 || oct[0] > 239)
        return fail(r, "%ld.%ld.%ld.%ld is not a multicast address (224.0.0.0 to "
                    "239.255.255.255): udpm needs a multicast group",
                    oct[0], oct[1], oct[2], oct[3]);
    u->has_group = true;
    snprintf(u->group, sizeof u->group, "%ld.%ld.%ld.%ld", oct[0], oct[1], oct[2], oct[3]);
    return true;
}

/* :PORT after a group; LCM's default when absent. */
static bool read_port(url_reader *r)
{
    r->u->port = LAG_URL_DEFAULT_PORT;
    if (!r->u->has_group || *r->p != ':') return true;
    r->p++;
    long port;
    /* a plant's commands go to the next port (lagsim_bus.h) */
    if (!read_uint(&r->p, 5, &port) || port < 1 || port > 65534)
        return fail(r, "expected a port from 1 to 65534 (commands go to the next port) "
                    "after the group in '%s'", r->url);
    r->u->has_port = true;
    r->u->port = (int)port;
    return true;
}

static bool read_end_of_address(url_reader *r)
{
    if (*r->p != '\0' && *r->p != '?')
        return fail(r, "unexpected '%c' after the address in '%s' (expected "
                    "udpm://GROUP:PORT?option=value&...)", *r->p, r->url);
    r->u->query = r->p;
    return true;
}

/* One option of a scene's URL, KEY=<integer>, at p; leaves p at its '&' or the end. */
static bool read_option(url_reader *r, bool *seen_ttl, bool *seen_buf)
{
    const char *p = r->p, *eq = p;
    while (*eq && *eq != '=' && *eq != '&') eq++;
    int klen = (int)(eq - p);
    bool is_ttl = klen == 3 && strncmp(p, "ttl", 3) == 0;
    bool is_buf = klen == 13 && strncmp(p, "recv_buf_size", 13) == 0;
    if (!is_ttl && !is_buf)
        return fail(r, "unknown udpm option '%.*s' in '%s'; allowed: ttl, recv_buf_size",
                    klen > 32 ? 32 : klen, p, r->url);
    if ((is_ttl && *seen_ttl) || (is_buf && *seen_buf))
        return fail(r, "udpm option '%.*s' given twice in '%s'", klen, p, r->url);
    const char *v = eq;
    long val;
    if (*v++ != '=' || !read_uint(&v, 10, &val) || (*v != '\0' && *v != '&'))
        return fail(r, "expected %.*s=<integer> in '%s'", klen, p, r->url);
    r->p = v;
    if (is_buf) {
        *seen_buf = true;
        if (val < 4096 || val > 268435456)
            return fail(r, "recv_buf_size must be 4096 to 268435456 bytes, got %ld", val);
        r->u->recv_buf_size = val;
        return true;
    }
    *seen_ttl = true;
    if (val > 255) return fail(r, "ttl must be 0 to 255, got %ld", val);
    if (val > 0 && !(r->flags & LAG_URL_ALLOW_LAN))
        return fail(r, "ttl=%ld sends every message beyond this host (1: the local network, "
                    "more: through routers); set lcm.allow_lan: true if that is meant, or use "
                    "ttl=0", val);
    r->u->ttl = (int)val;
    return true;
}

/* ?OPTIONS under a scene's rules (kept as given otherwise). */
static bool read_options(url_reader *r)
{
    if (!(r->flags & LAG_URL_SCENE_RULES) || *r->p != '?') return true;
    bool seen_ttl = false, seen_buf = false;
    r->p++;
    for (;;) {
        if (!read_option(r, &seen_ttl, &seen_buf)) return false;
        if (*r->p == '\0') return true;
        r->p++; /* past '&' */
    }
}

int lag_url_parse(const char *url, int flags, lag_url *u, char *err, size_t errlen)
{
    memset(u, 0, sizeof *u);
    u->query = "";
    if (err && errlen) err[0] = '\0';
    url_reader r = {.url = url, .p = url, .flags = flags, .u = u, .err = err, .errlen = errlen};
    if (!read_provider(&r)) return -1;
    if (u->provider == LAG_URL_MEMQ) return 0;
    bool ok = read_group(&r) && read_port(&r) && read_end_of_address(&r) && read_options(&r);
    return ok ? 0 : -1;
}

int lag_url_format(const lag_url *u, int port, char *out, size_t len)
{
    if (u->provider == LAG_URL_MEMQ) return snprintf(out, len, "memq://");
    return snprintf(out, len, "udpm://%s:%d%s", u->group, port, u->query);
}
