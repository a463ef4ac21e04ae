/*
 * lagsim's wire format: bounded encoding and decoding of every lagsim LCM message
 * (joint_state_t, joint_command_t, control_t, event_t, status_t, scene_t, reference_t),
 * shared by the
 * daemon, the C client library, --replay and the log tools.
 *
 * Why not lcm-gen's C decoders: they trust the payload. A string or array length read
 * from the bytes goes straight to malloc and memcpy (a length of -1 is a crash, a length
 * of 30000 a 240 kB allocation that leaks when a later field fails), and every decoded
 * message is a tree of heap blocks to free. The decoders here:
 *   - read at most `len` bytes and never allocate: each message type has a fixed-size C
 *     struct (capacities below), and every string and array length is checked against
 *     the bytes left and against its field's capacity before anything is copied;
 *   - bound every array count by the field's capacity and, for joint arrays, by the
 *     caller's `max_joints` (the daemon passes its model's joint count);
 *   - require each string to be 1 + n bytes ending in its only NUL (a name "x\0y" must
 *     not match joint "x"), each boolean to be 0 or 1, and no bytes after the message, so
 *     that a message decodes only if encoding the result gives back exactly its bytes;
 *   - on failure leave *out zeroed except for the fields read before the failure (after
 *     LAG_WIRE_ECOUNT the count field holds the count read, for the caller's message).
 * The encoders write the same format from the same structs, refuse a count above the
 * capacity, a string without its NUL, and any NaN or infinity (nothing non-finite goes on
 * the bus), and never write past `cap`.
 *
 * One table per type (lagsim_wire.c) lists its fields in .lcm order; encoder, decoder,
 * the fingerprint check and the tools all walk it. The fingerprint a message must carry
 * is lcm-gen's own (__lagsim_<type>_get_hash), and lag_wire_table_fingerprint() recomputes
 * it from the table with LCM's algorithm: a unit test requires the two to agree for every
 * type, so editing a .lcm file without the table (or the reverse) fails the build's tests.
 *
 * Decoded doubles are returned as sent, NaN and infinity included: whether a non-finite
 * number is an error is the caller's decision (lag_wire_all_finite helps).
 */
#ifndef LAGSIM_WIRE_H
#define LAGSIM_WIRE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Capacities of the fixed-size structs. */
#define LAG_WIRE_MAX_JOINTS 8    /* num_joints of any message */
#define LAG_WIRE_MAX_PARAMS 16   /* scene_t.num_params */
#define LAG_WIRE_NAME_LEN 64     /* names, kinds, modes, prefix: 63 bytes + NUL */
#define LAG_WIRE_TEXT_LEN 256    /* event_t.detail: 255 bytes + NUL */
/* No message of these types encodes to more bytes than this (checked by a unit test
 * against lag_wire_max_size). */
#define LAG_WIRE_BUF_SIZE 4096

/* The message types, in the order of their tables. */
typedef enum lag_wire_type {
    LAG_WIRE_JOINT_STATE = 0,
    LAG_WIRE_JOINT_COMMAND,
    LAG_WIRE_CONTROL,
    LAG_WIRE_EVENT,
    LAG_WIRE_STATUS,
    LAG_WIRE_SCENE,
    LAG_WIRE_REFERENCE,
    LAG_WIRE_TYPE_COUNT
} lag_wire_type;

/* Results: 0 is success, every failure is negative. */
typedef enum lag_wire_result {
    LAG_WIRE_OK = 0,
    LAG_WIRE_EFINGERPRINT = -1, /* not this type (or fewer than 8 bytes) */
    LAG_WIRE_ESHORT = -2,       /* the payload ends inside the message */
    LAG_WIRE_ECOUNT = -3,       /* an array count < 0 or above its bound */
    LAG_WIRE_ESTRING = -4,      /* a string length < 1, no final NUL, or a NUL inside */
    LAG_WIRE_ETOOLONG = -5,     /* a well-formed string longer than its field (the rest
                                 * of the message was decoded; the field holds its first
                                 * bytes) */
    LAG_WIRE_EVALUE = -6,       /* a boolean other than 0 or 1 */
    LAG_WIRE_ETRAILING = -7,    /* bytes after the end of the message */
    LAG_WIRE_ENONFINITE = -8,   /* encode: a NaN or infinity */
    LAG_WIRE_ESPACE = -9,       /* encode: the buffer is too small */
    LAG_WIRE_EARG = -10         /* a bad argument (unknown type, NULL pointer) */
} lag_wire_result;

/* <PREFIX>_STATE: one state of the simulated model. */
typedef struct lag_wire_joint_state {
    int64_t utime;                                   /* wall clock at publication, us */
    double sim_time;                                 /* s */
    int64_t step;                                    /* integrator ticks since reset */
    int16_t num_joints;
    char name[LAG_WIRE_MAX_JOINTS][LAG_WIRE_NAME_LEN];
    double position[LAG_WIRE_MAX_JOINTS];            /* q: m or rad */
    double velocity[LAG_WIRE_MAX_JOINTS];            /* qd: m/s or rad/s */
    double effort[LAG_WIRE_MAX_JOINTS];              /* N or N m */
    int64_t generation;                              /* the run and scene it belongs to
                                                      * (0 in a 0.1.0 log) */
} lag_wire_joint_state;

/* <PREFIX>_COMMAND: a controller's efforts. */
typedef struct lag_wire_joint_command {
    int64_t utime;
    double sim_time;                                 /* the state this command answers */
    int16_t num_joints;
    char name[LAG_WIRE_MAX_JOINTS][LAG_WIRE_NAME_LEN];
    double effort[LAG_WIRE_MAX_JOINTS];
    int64_t generation;                              /* of the state it answers; 0: none */
} lag_wire_joint_command;

/* RESET and RESET_TO's count, a bit set (lcmtypes/control_t.lcm): the scene file's values
 * too (RESET only), then wait for the first command (run_state waiting). The client
 * library's LAG_CLIENT_RESET_* are these (checked where it is compiled). */
#define LAG_WIRE_RESET_SCENE 1
#define LAG_WIRE_RESET_WAIT 2

/* <PREFIX>_CONTROL: pause, resume, step, reset, reset_to, status, describe, set. */
typedef struct lag_wire_control {
    int64_t utime;
    int8_t request;                                  /* LAGSIM_CONTROL_T_* */
    int64_t count;                                   /* STEP: periods; RESET, RESET_TO:
                                                      * LAG_WIRE_RESET_* bits */
    int16_t num_joints;                              /* RESET_TO */
    double q[LAG_WIRE_MAX_JOINTS];
    double qd[LAG_WIRE_MAX_JOINTS];
    char key[LAG_WIRE_NAME_LEN];                     /* SET: parameters.m2, effects.... */
    char value[LAG_WIRE_TEXT_LEN];                   /* SET: YAML */
} lag_wire_control;

/* <PREFIX>_EVENT: something happened. */
typedef struct lag_wire_event {
    int64_t utime;
    double sim_time;
    int64_t step;
    char kind[LAG_WIRE_NAME_LEN];
    char joint[LAG_WIRE_NAME_LEN];
    double value;
    char detail[LAG_WIRE_TEXT_LEN];
} lag_wire_event;

/* <PREFIX>_STATUS: the daemon's health (field meanings in lcmtypes/status_t.lcm). */
typedef struct lag_wire_status {
    int64_t utime;
    double sim_time;
    int64_t step;
    double wall_time;
    double rtf;
    int64_t overruns;
    double step_time_max_us;
    double step_time_mean_us;
    double energy;
    char integrator[LAG_WIRE_NAME_LEN];
    char mode[LAG_WIRE_NAME_LEN];
    char run_state[LAG_WIRE_NAME_LEN];
    int64_t commands_accepted;
    int64_t rejected_unknown_joint;
    int64_t rejected_unactuated;
    int64_t rejected_nonfinite;
    int64_t rejected_bad_length;
    int64_t rejected_undecodable;
    int64_t controls_rejected;
    bool watchdog_tripped;
    int64_t watchdog_trips;
    int64_t lockstep_timeouts;
    int64_t numeric_faults;
    int64_t rejected_stale;
    int64_t overrun_bursts;
    int64_t states_published;
    int64_t rejected_effort_limit;
    int64_t lockstep_retries;
    int64_t commands_ignored;
    char contact[LAG_WIRE_NAME_LEN]; /* the stick's floor: flight, contact, flat or "" */
    int64_t plant_conflicts;
    char waiting_for[LAG_WIRE_TEXT_LEN]; /* what the plant waits for, where; "" */
    double waiting_s;
    char waiting_got[LAG_WIRE_TEXT_LEN]; /* what came instead; "" */
    int64_t commands_wrong_port;
    double error_estimate;           /* m or rad, the live error estimate (docs/accuracy.md) */
    char error_joint[LAG_WIRE_NAME_LEN];
    double error_budget;             /* m or rad per period; 0 without integrator.error */
    int64_t error_warnings;
} lag_wire_status;

/* <PREFIX>_SCENE: the scene description. */
typedef struct lag_wire_scene {
    int64_t utime;
    char model[LAG_WIRE_NAME_LEN];
    char prefix[LAG_WIRE_NAME_LEN];
    int16_t num_params;
    char param_name[LAG_WIRE_MAX_PARAMS][LAG_WIRE_NAME_LEN];
    double param_value[LAG_WIRE_MAX_PARAMS];
    int16_t num_joints;
    char joint_name[LAG_WIRE_MAX_JOINTS][LAG_WIRE_NAME_LEN];
    bool actuated[LAG_WIRE_MAX_JOINTS];
    double initial_q[LAG_WIRE_MAX_JOINTS];
    double initial_qd[LAG_WIRE_MAX_JOINTS];
    double dt;
    double control_period;
    char integrator[LAG_WIRE_NAME_LEN];
    char mode[LAG_WIRE_NAME_LEN];
    double rate;
    double command_timeout;
    char effects[LAG_WIRE_NAME_LEN];                 /* effects on, comma-separated */
    bool limit_on[LAG_WIRE_MAX_JOINTS];              /* the joint has stops */
    double limit_lower[LAG_WIRE_MAX_JOINTS];         /* m or rad, 0 where no stops */
    double limit_upper[LAG_WIRE_MAX_JOINTS];
    int64_t generation;                              /* the generation it describes */
} lag_wire_scene;

/* <PREFIX>_REFERENCE: what the joints with a reference should follow, at a state's time. */
typedef struct lag_wire_reference {
    int64_t utime;
    double sim_time;                                 /* the state's sim_time */
    int64_t step;                                    /* the state's step */
    int16_t num_joints;                              /* joints with a reference */
    char name[LAG_WIRE_MAX_JOINTS][LAG_WIRE_NAME_LEN];
    double r[LAG_WIRE_MAX_JOINTS];                   /* m or rad */
    double rdot[LAG_WIRE_MAX_JOINTS];                /* m/s or rad/s */
    int64_t generation;                              /* the state's generation */
    double rddot[LAG_WIRE_MAX_JOINTS];               /* m/s^2 or rad/s^2 */
} lag_wire_reference;

/* ---------------------------------------------------------------- per type */
/* Decoders. max_joints bounds num_joints (clamped to [0, LAG_WIRE_MAX_JOINTS]). OUT: out */
int lag_wire_decode_joint_state(const void *data, size_t len, int max_joints,
                                lag_wire_joint_state *out);
int lag_wire_decode_joint_command(const void *data, size_t len, int max_joints,
                                  lag_wire_joint_command *out);
int lag_wire_decode_control(const void *data, size_t len, int max_joints,
                            lag_wire_control *out);
int lag_wire_decode_event(const void *data, size_t len, lag_wire_event *out);
int lag_wire_decode_status(const void *data, size_t len, lag_wire_status *out);
int lag_wire_decode_scene(const void *data, size_t len, int max_joints, lag_wire_scene *out);
int lag_wire_decode_reference(const void *data, size_t len, int max_joints,
                              lag_wire_reference *out);

/* Encoders: return the number of bytes written to buf (> 0) or a negative result. */
int lag_wire_encode_joint_state(const lag_wire_joint_state *m, void *buf, size_t cap);
int lag_wire_encode_joint_command(const lag_wire_joint_command *m, void *buf, size_t cap);
int lag_wire_encode_control(const lag_wire_control *m, void *buf, size_t cap);
int lag_wire_encode_event(const lag_wire_event *m, void *buf, size_t cap);
int lag_wire_encode_status(const lag_wire_status *m, void *buf, size_t cap);
int lag_wire_encode_scene(const lag_wire_scene *m, void *buf, size_t cap);
int lag_wire_encode_reference(const lag_wire_reference *m, void *buf, size_t cap);

/* ---------------------------------------------------------------- any type */
/* The same, for a type chosen at run time; out / m point to that type's struct. */
int lag_wire_decode(lag_wire_type t, const void *data, size_t len, int max_joints, void *out);
int lag_wire_encode(lag_wire_type t, const void *m, void *buf, size_t cap);
/* The type whose fingerprint the payload starts with, or -1. */
int lag_wire_identify(const void *data, size_t len);

/* Earlier versions of the types (docs/wire.md, "How message types evolve"): a type
 * changes only by fields appended at its end, and the wire module keeps, for each version
 * that changed it, how many of today's fields that version had and its fingerprint (what
 * lcm-gen gave it). Live traffic is today's version only (lag_wire_decode); what was
 * recorded (logs) is read in any version: */
/* The type and version of a payload, today's or an earlier one's: the type (or -1), and
 * in *written_by NULL for today's version or the lagsim version whose types wrote it
 * ("0.1.0"). */
int lag_wire_identify_any(const void *data, size_t len, const char **written_by);
/* lag_wire_decode for a message of today's version or an earlier one: the fields that
 * version did not have are 0 (a 0.1.0 state: generation 0); *written_by as above (may be
 * NULL). */
int lag_wire_decode_any(lag_wire_type t, const void *data, size_t len, int max_joints,
                        void *out, const char **written_by);
/* The lagsim version whose types these are (project(VERSION), "0.2.0"). */
const char *lag_wire_version(void);
/* The earlier versions of t: how many (0 for a type never changed), and the k-th's lagsim
 * version, field count and fingerprint (as lcm-gen gave it then). */
int lag_wire_old_versions(lag_wire_type t);
const char *lag_wire_old_version(lag_wire_type t, int k, int *nfields, int64_t *fingerprint);
/* LCM's fingerprint of the first nfields fields of t's table (the whole table: as
 * lag_wire_table_fingerprint). */
int64_t lag_wire_table_fingerprint_n(lag_wire_type t, int nfields);
/* The fingerprint a message of type t starts with (lcm-gen's). */
int64_t lag_wire_fingerprint(lag_wire_type t);
/* The fingerprint LCM's algorithm gives for the field table of t (equal to the above
 * when the table matches the .lcm file). */
int64_t lag_wire_table_fingerprint(lag_wire_type t);
/* "joint_state_t", ... (NULL for an unknown type). */
const char *lag_wire_type_name(lag_wire_type t);
/* A control_t request by its value: "PAUSE", ..., "SET", the constants of
 * lcmtypes/control_t.lcm (NULL for a value that is none of them). */
const char *lag_wire_request_name(int request);
/* sizeof the type's struct (0 for an unknown type). */
size_t lag_wire_struct_size(lag_wire_type t);
/* Largest encoding of a message of type t (every array and string full). */
size_t lag_wire_max_size(lag_wire_type t);
/* True when every double of the message is finite. */
bool lag_wire_all_finite(lag_wire_type t, const void *m);
/* A sentence for a result code. */
const char *lag_wire_result_string(int r);

/* ---------------------------------------------------------------- field tables */
/* LCM primitive types used by lagsim's messages. */
typedef enum lag_wire_kind {
    LAG_WIRE_INT8 = 0,
    LAG_WIRE_INT16,
    LAG_WIRE_INT64,
    LAG_WIRE_DOUBLE,
    LAG_WIRE_BOOLEAN,
    LAG_WIRE_STRING
} lag_wire_kind;

/* One field of a message, as in the .lcm file. */
typedef struct lag_wire_field {
    const char *name;      /* as in the .lcm file and the struct */
    lag_wire_kind kind;
    int count_field;       /* arrays: index (in this table) of the field holding the count;
                            * -1 for a scalar */
    int capacity;          /* arrays: elements the struct holds; count fields: their bound;
                            * 0 otherwise */
    bool joint_count;      /* count fields: bounded by the caller's max_joints too */
    size_t size;           /* bytes of one element in the struct (strings: with the NUL) */
    size_t offset;         /* offsetof in the struct */
} lag_wire_field;

/* The field table of t, in wire order (NULL and *n = 0 for an unknown type). */
const lag_wire_field *lag_wire_fields(lag_wire_type t, int *n);
/* "int8_t", "int16_t", "int64_t", "double", "boolean", "string". */
const char *lag_wire_kind_name(lag_wire_kind k);

#ifdef __cplusplus
}
#endif
#endif
