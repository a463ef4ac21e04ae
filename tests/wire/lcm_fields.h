/*
 * The members of an .lcm file, read independently of lcm-gen and of the wire module's
 * tables: what the tests compare those with. Header-only (static functions).
 */
#ifndef LAGSIM_TEST_LCM_FIELDS_H
#define LAGSIM_TEST_LCM_FIELDS_H

#include <ctype.h>
#include <stdio.h>
#include <string.h>

typedef struct lcm_field {
    char type[32], name[64], dim[64]; /* dim "" for a scalar */
} lcm_field;

/* Reads the members of the one struct in an .lcm file: "type name;" or
 * "type name[dim];", skipping comments and "const" lines. Returns the count or -1. */
static int parse_lcm(const char *path, lcm_field *out, int cap)
{
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    static char text[65536];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    /* strip comments */
    for (char *p = text; *p; p++) {
        if (p[0] == '/' && p[1] == '/')
            while (*p && *p != '\n') *p++ = ' ';
        if (!*p) break;
    }
    char *body = strchr(text, '{');
    if (!body) return -1;
    body++;
    int count = 0;
    char *save = NULL;
    for (char *st = strtok_r(body, ";}", &save); st; st = strtok_r(NULL, ";}", &save)) {
        while (isspace((unsigned char)*st)) st++;
        if (!*st || strncmp(st, "const ", 6) == 0) continue;
        if (count == cap) return -1;
        lcm_field *fd = &out[count];
        char rest[128] = "";
        if (sscanf(st, "%31s %127[^\n]", fd->type, rest) != 2) return -1;
        char *br = strchr(rest, '[');
        fd->dim[0] = '\0';
        if (br) {
            sscanf(br + 1, "%63[^] ]", fd->dim);
            *br = '\0';
        }
        sscanf(rest, "%63s", fd->name);
        count++;
    }
    return count;
}

#endif
