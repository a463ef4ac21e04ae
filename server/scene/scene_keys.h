/*
 * The loader's machinery shared by the files of key tables (private to the scene loader):
 * the conversion state, a key table's row, the readers of numbers, names and sections
 * that report an error at the node (scene_schema.c), and the effects' keys
 * (scene_effects.c). docs/scenes.md "Adding a scene key" says how they are used.
 */
#ifndef LAGSIM_SCENE_KEYS_H
#define LAGSIM_SCENE_KEYS_H

#include <stdbool.h>
#include <stddef.h>

#include "scene.h"
#include "scene_yaml.h"

/* The longest sim time (scene.h explains the bound). */
#define T_MAX LAG_SCENE_MAX_TIME
/* The largest force-like value (N or N m, N s or N m s, N s/m): the core's bound on a
 * disturbance (lagsim.h says why), for every such key. */
#define F_MAX LAG_FORCE_MAX

/* A number's range, with its unit for the message; each is written next to the key that
 * reads it, with the reason for its bounds. */
typedef struct range {
    double lo, hi;
    bool lo_open;      /* lo excluded ("> 0") */
    const char *unit;  /* shown in messages; NULL for none */
} range;

/* an effort bound: realtime.effort_limit, effects.actuator.<joint>.max */
static const range R_EFFORT = {0.0, F_MAX, true, "N or N m"};

/* The conversion's state: where it writes, and what the keys read so far left for the
 * checks of later keys. */
typedef struct conv {
    errbuf *err;
    lag_scene *sc;
    const lag_model_info *info;
    /* nodes remembered for the cross-checks (NULL if not given) */
    const ynode *root, *publish_hz, *dt, *integrator, *explode_limit, *url, *rate, *start;
    /* effects */
    const ynode *gravity_g_node;
    int gravity_enabled;  /* -1 not said, 0 off, 1 on */
    double gravity_g;
    int limit_seen;       /* bits: lower, upper given for the joint being read */
    int cur_joint;        /* the joint whose sub-mapping is being read */
    lag_disturbance *cur_dist; /* the disturbance being read */
    lag_reference *cur_ref;    /* the reference being read */
    int cur_ref_kind;          /* its kind, -1 before its type is known */
    unsigned cur_ref_seen;     /* LAG_REF_KEY_* given */
    int cur_dist_kind;    /* bits: impulse, force given */
} conv;

/* Key tables: a NULL-terminated list of {name, handler, what the value is}. The handler
 * reads the value; the type (and the sub-table of a section) lets scene_schema_each_number
 * list every numeric key, so that a test can check each one has a range. */
typedef struct keyrow keyrow;
typedef int (*key_fn)(conv *cv, const ynode *val, const char *path);
typedef enum keytype {
    K_OTHER = 0, /* a string, a name, a boolean */
    K_NUMBER,    /* a number */
    K_INTEGER,   /* an integer */
    K_MAP,       /* a section: the keys of `sub` */
    K_JOINTS,    /* {joint: number}, or {joint: {keys of sub}}; plus the keys of `extra` */
    K_VECTOR,    /* a sequence of one number per coordinate */
    K_LIST,      /* a sequence of mappings with the keys of `sub` */
    K_PARAMS     /* the model's parameters (lag_model_info) */
} keytype;
struct keyrow {
    const char *name;
    key_fn fn;
    keytype type;
    const keyrow *sub, *extra;
};

typedef int (*joint_fn)(conv *cv, int joint, const ynode *val, const char *path);


/* scene_schema.c: the readers. Each reads the node `nd` at key path `path`; on a bad
 * value it writes "file:line:column: path: what was expected" to cv->err and returns -1. */
const char *sch_join(char *buf, size_t len, const char *parent, const char *key);
int sch_need_map(conv *cv, const ynode *nd, const char *path, const char *what);
int sch_convert_map(conv *cv, const ynode *nd, const char *path, const keyrow *rows,
                    const char *what);
int sch_get_number(conv *cv, const ynode *nd, const char *path, double *out);
int sch_get_in(conv *cv, const ynode *nd, const char *path, double lo, double hi,
               bool lo_open, const char *unit, double *out);
int sch_get_range(conv *cv, const ynode *nd, const char *path, const range *r, double *out);
int sch_get_magnitude(conv *cv, const ynode *nd, const char *path, const range *r,
                      double *out);
int sch_get_int(conv *cv, const ynode *nd, const char *path, long long lo, long long hi,
                long long *out);
int sch_get_string(conv *cv, const ynode *nd, const char *path, const char *what,
                   const char **out);
int sch_get_bool(conv *cv, const ynode *nd, const char *path, bool *out);
void sch_joint_list(const conv *cv, char *buf, size_t len);
int sch_joint_index(const conv *cv, const char *name);
int sch_per_joint(conv *cv, const ynode *nd, const char *path, joint_fn fn);
int sch_need_actuated(conv *cv, int j, const ynode *nd, const char *path);
int sch_get_within_explode(conv *cv, const ynode *nd, const char *path, double *out);

/* scene_effects.c: the `effects:` section, one row per effect (gravity, then the core's
 * effects by their scene keys). */
extern const keyrow k_effects[];
int key_effects(conv *cv, const ynode *nd, const char *path);

#endif
