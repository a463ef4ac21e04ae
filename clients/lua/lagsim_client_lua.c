/*
 * lagsim_client: the client library (lagsim_client.h) from Lua 5.2, a C module, so that
 * the Lua controllers follow the protocol by the library's code (the plant's two URLs,
 * finding the plant, DESCRIBE until the scene comes, each state once with its copies
 * answered, the scene rule, the generation on every command, every message decoded whole
 * and bounded), not by a copy of it in Lua.
 *
 *   local lc = require('lagsim_client')       -- or lagsim_lcm.client(): found for you
 *   local state_url, command_url = lc.plant_urls(url)        -- nil, message if refused
 *   local where, url = lc.locate('ALICE')      -- 'host', the URL a host's directory names
 *                                              -- ('here', 'none': the default bus's)
 *   local c = assert(lc.new('DIPC', url))      -- url nil: LCM_DEFAULT_URL, else LCM's default
 *   local scene = c:wait_scene(0.25)           -- a table of scene_t's fields, or nil
 *   local st = c:wait_state(0.05)              -- a table of joint_state_t's fields, or nil
 *   c:send_command(st.sim_time, {'theta0'}, {u})
 *   c:stopped()                                -- the daemon's stop event came
 *   c:counters()                               -- {states=, dropped=, repeats=, held=, ...}
 *   c:close()                                  -- or left to the garbage collector
 *
 * Arrays are 1-based Lua tables; integers (utime, step, generation) are Lua numbers
 * (doubles: exact up to 2^53). A library error is raised as a Lua error with its message;
 * nothing arriving in time is nil. No Lua callback runs inside the library: the module
 * notes the stop event itself, so a Lua error can never unwind through C.
 *
 * Linked with the static client library (liblagsim_client.a), as the installed C++
 * example is: the module needs no run-time path to find it wherever it is installed.
 */
#include <lauxlib.h>
#include <lua.h>
#include <math.h>
#include <string.h>

#include "lagsim_client.h"

#define MT "lagsim_client.handle"

typedef struct handle {
    lag_client *c;
    lag_client_scene *sc;
    int stopped; /* the daemon's stop event came */
} handle;

static void on_event(const lag_client_event *ev, void *user)
{
    if (strcmp(ev->kind, "stop") == 0) ((handle *)user)->stopped = 1;
}

static const char *opt_string(lua_State *L, int i)
{
    const char *s = luaL_optstring(L, i, NULL);
    return s && s[0] ? s : NULL;
}

static void set_number(lua_State *L, const char *k, double v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

static void set_string(lua_State *L, const char *k, const char *v)
{
    lua_pushstring(L, v ? v : "");
    lua_setfield(L, -2, k);
}

static void set_numbers(lua_State *L, const char *k, const double *v, int n)
{
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        lua_pushnumber(L, v[i]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -2, k);
}

static void set_names(lua_State *L, const char *k, const char (*names)[LAG_CLIENT_NAME_LEN],
                      int n)
{
    lua_createtable(L, n, 0);
    for (int i = 0; i < n; i++) {
        lua_pushstring(L, names[i]);
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -2, k);
}

static handle *check(lua_State *L)
{
    handle *h = luaL_checkudata(L, 1, MT);
    if (!h->c) luaL_error(L, "lagsim_client: the handle is closed");
    return h;
}

/* A library error (rc < 0) as a Lua error; else rc. */
static int ok_or_raise(lua_State *L, handle *h, int rc)
{
    if (rc < 0) return luaL_error(L, "lagsim_client: %s", lag_client_errmsg(h->c));
    return rc;
}

/* ---------------------------------------------------------------- functions */

static int l_plant_urls(lua_State *L)
{
    char s[LAG_CLIENT_URL_LEN], c[LAG_CLIENT_URL_LEN], err[256];
    if (lag_client_plant_urls(opt_string(L, 1), s, sizeof s, c, sizeof c, err, sizeof err) !=
        LAG_CLIENT_OK) {
        lua_pushnil(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushstring(L, s);
    lua_pushstring(L, c);
    return 2;
}

/* pick_plant(url, model, wait_s) -> plant table | nil, message, 'timeout'|'ambiguous'|'error' */
static int l_pick_plant(lua_State *L)
{
    lag_client_plant p;
    char err[1200];
    int rc = lag_client_pick_plant(opt_string(L, 1), opt_string(L, 2), luaL_checknumber(L, 3),
                                   &p, sizeof p, err, sizeof err);
    if (rc != LAG_CLIENT_OK) {
        lua_pushnil(L);
        lua_pushstring(L, err);
        lua_pushstring(L, rc == LAG_CLIENT_TIMEOUT     ? "timeout"
                          : rc == LAG_CLIENT_ERR_AMBIGUOUS ? "ambiguous"
                                                           : "error");
        return 3;
    }
    lua_createtable(L, 0, 7);
    set_string(L, "prefix", p.prefix);
    set_string(L, "model", p.model);
    set_string(L, "mode", p.mode);
    set_string(L, "run_state", p.run_state);
    set_string(L, "host", p.host);
    set_string(L, "url", p.url);
    set_number(L, "sim_time", p.sim_time);
    return 1;
}

static int l_plants_instead(lua_State *L)
{
    char out[1500];
    lag_client_plants_instead(opt_string(L, 1), luaL_checkstring(L, 2), luaL_checknumber(L, 3),
                              out, sizeof out);
    lua_pushstring(L, out);
    return 1;
}

/* locate(prefix[, wait_s]) -> 'host'|'here'|'none', url | nil, message (lag_client_locate:
 * where the plant on prefix runs when no URL was given; url the host's directory's for
 * 'host', else the default bus's) */
static int l_locate(lua_State *L)
{
    char url[LAG_CLIENT_URL_LEN], err[256];
    int where = lag_client_locate(luaL_checkstring(L, 1),
                                  luaL_optnumber(L, 2, LAG_CLIENT_LOCATE_WAIT_S), url,
                                  sizeof url, err, sizeof err);
    if (where < 0) {
        lua_pushnil(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushstring(L, where == LAG_CLIENT_LOCATE_HOST   ? "host"
                      : where == LAG_CLIENT_LOCATE_HERE ? "here"
                                                        : "none");
    lua_pushstring(L, url);
    return 2;
}

static int l_now(lua_State *L)
{
    lua_pushnumber(L, lag_client_now());
    return 1;
}

static int l_new(lua_State *L)
{
    const char *prefix = luaL_checkstring(L, 1), *url = opt_string(L, 2);
    char err[256];
    handle *h = lua_newuserdata(L, sizeof *h);
    memset(h, 0, sizeof *h);
    luaL_setmetatable(L, MT);
    h->c = lag_client_create(url, prefix, err, sizeof err);
    if (!h->c) {
        lua_pushnil(L);
        lua_pushstring(L, err);
        return 2;
    }
    h->sc = lag_client_scene_new();
    if (!h->sc) return luaL_error(L, "lagsim_client: out of memory");
    lag_client_on_event(h->c, on_event, h);
    return 1;
}

/* ---------------------------------------------------------------- a handle's methods */

/* The scene held (h->sc) as a table of scene_t's fields. */
static void push_scene(lua_State *L, const lag_client_scene *sc)
{
    static const char *const texts[] = {"integrator", "mode", "effects"};
    static const char *(*const text_fn[])(const lag_client_scene *) = {
        lag_client_scene_integrator, lag_client_scene_mode, lag_client_scene_effects};
    static const char *const nums[] = {"dt", "control_period", "rate", "command_timeout"};
    static double (*const num_fn[])(const lag_client_scene *) = {
        lag_client_scene_dt, lag_client_scene_control_period, lag_client_scene_rate,
        lag_client_scene_command_timeout};
    static const char *const per_joint[] = {"initial_q", "initial_qd", "limit_lower", "limit_upper"};
    static double (*const joint_fn[])(const lag_client_scene *, int) = {
        lag_client_scene_initial_q, lag_client_scene_initial_qd, lag_client_scene_limit_lower,
        lag_client_scene_limit_upper};
    int np = lag_client_scene_num_params(sc), nj = lag_client_scene_num_joints(sc);
    lua_createtable(L, 0, 24);
    set_string(L, "model", lag_client_scene_model(sc));
    set_string(L, "prefix", lag_client_scene_prefix(sc));
    for (int k = 0; k < 3; k++) set_string(L, texts[k], text_fn[k](sc));
    for (int k = 0; k < 4; k++) set_number(L, nums[k], num_fn[k](sc));
    set_number(L, "generation", (double)lag_client_scene_generation(sc));
    set_number(L, "utime", (double)lag_client_scene_utime(sc));
    set_number(L, "num_params", np);
    set_number(L, "num_joints", nj);
    lua_createtable(L, np, 0); /* param_name */
    lua_createtable(L, np, 0); /* param_value */
    for (int i = 0; i < np; i++) {
        lua_pushstring(L, lag_client_scene_param_name(sc, i));
        lua_rawseti(L, -3, i + 1);
        lua_pushnumber(L, lag_client_scene_param_value(sc, i));
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -3, "param_value");
    lua_setfield(L, -2, "param_name");
    lua_createtable(L, nj, 0); /* joint_name */
    lua_createtable(L, nj, 0); /* actuated */
    lua_createtable(L, nj, 0); /* limit_on */
    for (int i = 0; i < nj; i++) {
        lua_pushstring(L, lag_client_scene_joint_name(sc, i));
        lua_rawseti(L, -4, i + 1);
        lua_pushboolean(L, lag_client_scene_actuated(sc, i));
        lua_rawseti(L, -3, i + 1);
        lua_pushboolean(L, lag_client_scene_limit_on(sc, i));
        lua_rawseti(L, -2, i + 1);
    }
    lua_setfield(L, -4, "limit_on");
    lua_setfield(L, -3, "actuated");
    lua_setfield(L, -2, "joint_name");
    for (int k = 0; k < 4; k++) {
        double v[LAG_CLIENT_MAX_JOINTS];
        for (int i = 0; i < nj && i < LAG_CLIENT_MAX_JOINTS; i++) v[i] = joint_fn[k](sc, i);
        set_numbers(L, per_joint[k], v, nj < LAG_CLIENT_MAX_JOINTS ? nj : LAG_CLIENT_MAX_JOINTS);
    }
}

/* c:wait_scene(timeout_s) -> scene table | nil */
static int m_wait_scene(lua_State *L)
{
    handle *h = check(L);
    int rc = ok_or_raise(L, h, lag_client_wait_scene(h->c, luaL_checknumber(L, 2), h->sc));
    if (rc != LAG_CLIENT_OK) return 0;
    push_scene(L, h->sc);
    return 1;
}

/* c:latest_scene() -> the scene of the latest state's generation | nil */
static int m_latest_scene(lua_State *L)
{
    handle *h = check(L);
    if (!lag_client_latest_scene(h->c, h->sc)) return 0;
    push_scene(L, h->sc);
    return 1;
}

/* c:wait_state(timeout_s) -> state table | nil (copies: answered by the library) */
static int m_wait_state(lua_State *L)
{
    handle *h = check(L);
    lag_client_state st;
    int rc = ok_or_raise(L, h, lag_client_wait_state(h->c, luaL_checknumber(L, 2), &st, sizeof st));
    if (rc != LAG_CLIENT_OK) return 0;
    lua_createtable(L, 0, 9);
    set_number(L, "utime", (double)st.utime);
    set_number(L, "sim_time", st.sim_time);
    set_number(L, "step", (double)st.step);
    set_number(L, "generation", (double)st.generation);
    set_number(L, "num_joints", st.num_joints);
    set_names(L, "name", (const char (*)[LAG_CLIENT_NAME_LEN])st.name, st.num_joints);
    set_numbers(L, "position", st.position, st.num_joints);
    set_numbers(L, "velocity", st.velocity, st.num_joints);
    set_numbers(L, "effort", st.effort, st.num_joints);
    return 1;
}

/* c:latest_reference() -> reference table (reference_t's fields) | nil */
static int m_latest_reference(lua_State *L)
{
    handle *h = check(L);
    lag_client_reference r;
    if (!lag_client_latest_reference(h->c, &r, sizeof r)) return 0;
    lua_createtable(L, 0, 9);
    set_number(L, "utime", (double)r.utime);
    set_number(L, "sim_time", r.sim_time);
    set_number(L, "step", (double)r.step);
    set_number(L, "generation", (double)r.generation);
    set_number(L, "num_joints", r.num_joints);
    set_names(L, "name", (const char (*)[LAG_CLIENT_NAME_LEN])r.name, r.num_joints);
    set_numbers(L, "r", r.r, r.num_joints);
    set_numbers(L, "rdot", r.rdot, r.num_joints);
    set_numbers(L, "rddot", r.rddot, r.num_joints);
    return 1;
}

/* c:send_command(sim_time, names, efforts): answers the state at sim_time */
static int m_send_command(lua_State *L)
{
    handle *h = check(L);
    double t = luaL_checknumber(L, 2), e[LAG_CLIENT_MAX_JOINTS];
    const char *names[LAG_CLIENT_MAX_JOINTS];
    luaL_checktype(L, 3, LUA_TTABLE);
    luaL_checktype(L, 4, LUA_TTABLE);
    int n = (int)lua_rawlen(L, 3);
    if (n != (int)lua_rawlen(L, 4) || n > LAG_CLIENT_MAX_JOINTS)
        return luaL_error(L, "lagsim_client: send_command wants as many efforts as names, "
                             "at most %d", LAG_CLIENT_MAX_JOINTS);
    for (int i = 0; i < n; i++) {
        lua_rawgeti(L, 3, i + 1);
        names[i] = luaL_checkstring(L, -1); /* kept alive by the table */
        lua_pop(L, 1);
        lua_rawgeti(L, 4, i + 1);
        e[i] = luaL_checknumber(L, -1);
        lua_pop(L, 1);
    }
    ok_or_raise(L, h, lag_client_send_command(h->c, t, n, names, e));
    return 0;
}

static int m_counters(lua_State *L)
{
    handle *h = check(L);
    lag_client_counters k;
    lag_client_get_counters(h->c, &k, sizeof k);
    lua_createtable(L, 0, 12);
    set_number(L, "states", (double)k.states);
    set_number(L, "scenes", (double)k.scenes);
    set_number(L, "statuses", (double)k.statuses);
    set_number(L, "events", (double)k.events);
    set_number(L, "dropped", (double)k.dropped);
    set_number(L, "commands_sent", (double)k.commands_sent);
    set_number(L, "controls_sent", (double)k.controls_sent);
    set_number(L, "copies", (double)k.copies);
    set_number(L, "repeats", (double)k.repeats);
    set_number(L, "references", (double)k.references);
    set_number(L, "held", (double)k.held);
    set_number(L, "describes", (double)k.describes);
    return 1;
}

static int m_stopped(lua_State *L)
{
    lua_pushboolean(L, check(L)->stopped);
    return 1;
}

static int m_close(lua_State *L)
{
    handle *h = luaL_checkudata(L, 1, MT);
    lag_client_destroy(h->c);
    lag_client_scene_free(h->sc);
    h->c = NULL;
    h->sc = NULL;
    return 0;
}

int luaopen_lagsim_client(lua_State *L);
int luaopen_lagsim_client(lua_State *L)
{
    static const luaL_Reg methods[] = {
        {"wait_scene", m_wait_scene}, {"latest_scene", m_latest_scene},
        {"wait_state", m_wait_state}, {"latest_reference", m_latest_reference},
        {"send_command", m_send_command}, {"counters", m_counters},
        {"stopped", m_stopped}, {"close", m_close}, {NULL, NULL}};
    static const luaL_Reg functions[] = {
        {"plant_urls", l_plant_urls}, {"pick_plant", l_pick_plant},
        {"plants_instead", l_plants_instead}, {"locate", l_locate}, {"now", l_now},
        {"new", l_new}, {NULL, NULL}};
    luaL_newmetatable(L, MT);
    luaL_newlib(L, methods);
    lua_setfield(L, -2, "__index");
    lua_pushcfunction(L, m_close);
    lua_setfield(L, -2, "__gc");
    lua_pop(L, 1);
    luaL_newlib(L, functions);
    set_number(L, "abi", lag_client_abi());
    set_number(L, "version", lag_client_version());
    return 1;
}
