"""lagsim's client library (liblagsim_client.so.1) from Python, through ctypes: the
protocol's rules (the plant's two URLs, discovery, DESCRIBE until the scene comes, each
state once with its copies answered, the scene rule, the generation on every command,
every message decoded whole and bounded) are the C library's, not copied here.

    from lagsim_client import Client, plant_urls
    c = Client("DIPC")                  # url None: LCM_DEFAULT_URL, else LCM's default
    scene = c.wait_scene(5.0)           # a Scene, or None
    st = c.wait_state(0.1)              # a State not yet returned (copies answered), or None
    c.send_command(st.sim_time, ["theta0"], [u])

Which library is loaded, in this order (the first that loads; a clear error naming every
one tried if none does):
  1. $LAGSIM_CLIENT_LIBRARY, a path to liblagsim_client.so.1: when set, that library and
     no other (one it names that does not load is an error naming it, never skipped);
  2. the path CMake wrote into lagsim_client_path.py beside this module: the build tree's
     <build>/lib/liblagsim_client.so.1, or, once installed, the installed library;
  3. liblagsim_client.so.1 by the dynamic loader's search (ldconfig's cache, LD_LIBRARY_PATH).
It must have the ABI this module was written for (lag_client_abi() == ABI), and a release
at least VERSION_NUMBER (the functions used here).
"""
import ctypes
import os

__all__ = ["Client", "ClientError", "Plant", "discover", "locate", "pick_plant",
           "plants_instead", "plant_urls", "library", "ABI", "LOCATE_NONE", "LOCATE_HERE",
           "LOCATE_HOST", "LOCATE_WAIT_S"]

ABI = 1                 # LAGSIM_CLIENT_ABI this module was written for: the SONAME's number
VERSION_NUMBER = 2000   # the first release with every function used here (0.2.0)
SONAME = "liblagsim_client.so.%d" % ABI
MAX_JOINTS, NAME_LEN, TEXT_LEN, URL_LEN = 8, 64, 256, 320   # the header's capacities
OK, TIMEOUT, ERR_AMBIGUOUS = 0, 2, -4  # lagsim/result.h
LOCATE_NONE, LOCATE_HERE, LOCATE_HOST = 0, 1, 2  # lag_client_locate's answers
LOCATE_WAIT_S = 1.0  # LAG_CLIENT_LOCATE_WAIT_S: a host's directory names a plant every 0.5 s


class ClientError(RuntimeError):
    """A failure of the library (its message), or a library that cannot be used."""


class _State(ctypes.Structure):
    _fields_ = [("utime", ctypes.c_int64), ("sim_time", ctypes.c_double),
                ("step", ctypes.c_int64), ("generation", ctypes.c_int64),
                ("num_joints", ctypes.c_int32), ("reserved_", ctypes.c_int32),
                ("name", (ctypes.c_char * NAME_LEN) * MAX_JOINTS),
                ("position", ctypes.c_double * MAX_JOINTS),
                ("velocity", ctypes.c_double * MAX_JOINTS),
                ("effort", ctypes.c_double * MAX_JOINTS)]


class _Reference(ctypes.Structure):
    _fields_ = [("utime", ctypes.c_int64), ("sim_time", ctypes.c_double),
                ("step", ctypes.c_int64), ("generation", ctypes.c_int64),
                ("num_joints", ctypes.c_int32), ("reserved_", ctypes.c_int32),
                ("name", (ctypes.c_char * NAME_LEN) * MAX_JOINTS),
                ("r", ctypes.c_double * MAX_JOINTS), ("rdot", ctypes.c_double * MAX_JOINTS),
                ("rddot", ctypes.c_double * MAX_JOINTS)]


class _Event(ctypes.Structure):
    _fields_ = [("utime", ctypes.c_int64), ("sim_time", ctypes.c_double),
                ("step", ctypes.c_int64), ("value", ctypes.c_double),
                ("kind", ctypes.c_char * NAME_LEN), ("joint", ctypes.c_char * NAME_LEN),
                ("detail", ctypes.c_char * TEXT_LEN)]


class _Counters(ctypes.Structure):
    _fields_ = [(k, ctypes.c_int64) for k in (
        "states", "scenes", "statuses", "events", "dropped", "commands_sent",
        "controls_sent", "copies", "repeats", "references", "held", "describes")]


class _Plant(ctypes.Structure):
    _fields_ = [("sim_time", ctypes.c_double)] + \
        [(k, ctypes.c_char * NAME_LEN) for k in ("prefix", "model", "mode", "run_state", "host")] + \
        [("url", ctypes.c_char * URL_LEN)]


_EVENT_FN = ctypes.CFUNCTYPE(None, ctypes.POINTER(_Event), ctypes.c_void_p)
_P, _S, _D, _I, _B = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_double, ctypes.c_int, ctypes.c_bool
_SZ, _I64 = ctypes.c_size_t, ctypes.c_int64
# name: (result, arguments), as lagsim_client.h declares them
_SIGNATURES = {
    "lag_client_abi": (_I, []), "lag_client_version": (_I, []), "lag_client_now": (_D, []),
    "lag_client_plant_urls": (_I, [_S, _S, _SZ, _S, _SZ, _S, _SZ]),
    "lag_client_create": (_P, [_S, _S, _S, _SZ]), "lag_client_destroy": (None, [_P]),
    "lag_client_errmsg": (_S, [_P]),
    "lag_client_on_event": (None, [_P, _EVENT_FN, _P]),
    "lag_client_wait_scene": (_I, [_P, _D, _P]),
    "lag_client_wait_state": (_I, [_P, _D, ctypes.POINTER(_State), _SZ]),
    "lag_client_latest_reference": (_B, [_P, ctypes.POINTER(_Reference), _SZ]),
    "lag_client_latest_scene": (_B, [_P, _P]),
    "lag_client_send_command": (_I, [_P, _D, _I, ctypes.POINTER(_S), ctypes.POINTER(_D)]),
    "lag_client_get_counters": (None, [_P, ctypes.POINTER(_Counters), _SZ]),
    "lag_client_scene_new": (_P, []), "lag_client_scene_free": (None, [_P]),
    "lag_client_scene_generation": (_I64, [_P]), "lag_client_scene_utime": (_I64, [_P]),
    "lag_client_scene_num_params": (_I, [_P]), "lag_client_scene_param_name": (_S, [_P, _I]),
    "lag_client_scene_param_value": (_D, [_P, _I]), "lag_client_scene_num_joints": (_I, [_P]),
    "lag_client_scene_joint_name": (_S, [_P, _I]), "lag_client_scene_actuated": (_B, [_P, _I]),
    "lag_client_scene_initial_q": (_D, [_P, _I]), "lag_client_scene_initial_qd": (_D, [_P, _I]),
    "lag_client_scene_limit_on": (_B, [_P, _I]), "lag_client_scene_limit_lower": (_D, [_P, _I]),
    "lag_client_scene_limit_upper": (_D, [_P, _I]),
    "lag_client_pick_plant": (_I, [_S, _S, _D, ctypes.POINTER(_Plant), _SZ, _S, _SZ]),
    "lag_client_plants_instead": (_I, [_S, _S, _D, _S, _SZ]),
    "lag_client_locate": (_I, [_S, _D, _S, _SZ, _S, _SZ]),
}
for _k in ("model", "prefix", "integrator", "mode", "effects"):
    _SIGNATURES["lag_client_scene_" + _k] = (_S, [_P])
for _k in ("dt", "control_period", "rate", "command_timeout"):
    _SIGNATURES["lag_client_scene_" + _k] = (_D, [_P])

_lib = None


def _candidates():
    tried = []
    try:
        import lagsim_client_path  # written by CMake: the build tree's, or the install's
        tried.append(("lagsim_client_path.py", lagsim_client_path.LIBRARY))
    except ImportError:
        pass
    tried.append(("the dynamic loader (ldconfig, LD_LIBRARY_PATH)", SONAME))
    return tried


def library():
    """The loaded library (ctypes.CDLL), its functions typed; loaded on first use."""
    global _lib
    if _lib is not None:
        return _lib
    errors = []
    env = os.environ.get("LAGSIM_CLIENT_LIBRARY")
    if env:  # the user chose this one: used, or an error naming it (no silent fallback)
        try:
            lib, path = ctypes.CDLL(env), env
        except OSError as e:
            raise ClientError("cannot load lagsim's client library $LAGSIM_CLIENT_LIBRARY=%s: %s "
                              "(unset LAGSIM_CLIENT_LIBRARY to use the build's or the installed "
                              "library)" % (env, e))
        return _typed(lib, path)
    for where, path in _candidates():
        try:
            lib = ctypes.CDLL(path)
            break
        except OSError as e:
            errors.append("%s (%s): %s" % (path, where, e))
    else:
        raise ClientError("cannot load lagsim's client library; tried %s. Set "
                          "LAGSIM_CLIENT_LIBRARY=<build>/lib/%s, or install lagsim"
                          % ("; ".join(errors), SONAME))
    return _typed(lib, path)


def _typed(lib, path):
    """lib with its functions typed, once its ABI and release are checked; kept."""
    global _lib
    for name, (res, args) in _SIGNATURES.items():
        try:
            f = getattr(lib, name)
        except AttributeError:
            raise ClientError("%s has no %s: a release older than this module (%d)"
                              % (path, name, VERSION_NUMBER))
        f.restype, f.argtypes = res, args
    if lib.lag_client_abi() != ABI or lib.lag_client_version() < VERSION_NUMBER:
        raise ClientError("%s has ABI %d, release %d; this module needs ABI %d, release >= %d"
                          % (path, lib.lag_client_abi(), lib.lag_client_version(), ABI,
                             VERSION_NUMBER))
    _lib = lib
    return lib


def _b(s):
    return s.encode() if s else None


def _s(b):
    return b.decode("utf-8", "replace") if b is not None else None


def plant_urls(url=None):
    """(state URL, command URL) of the plant whose lcm.url is url (None or "": the
    environment's LCM_DEFAULT_URL, else LCM's default), by the library's rule
    (lag_client_plant_urls). Raises ValueError for a URL a plant cannot have."""
    s, c, e = (ctypes.create_string_buffer(URL_LEN) for _ in range(3))
    if library().lag_client_plant_urls(_b(url), s, URL_LEN, c, URL_LEN, e, URL_LEN) != OK:
        raise ValueError(_s(e.value))
    return _s(s.value), _s(c.value)


class State(object):
    """A state as the library returned it: utime, sim_time, step, generation, num_joints,
    and lists name, position, velocity, effort (joint_state_t's fields)."""
    __slots__ = ("utime", "sim_time", "step", "generation", "num_joints", "name", "position",
                 "velocity", "effort")

    def __init__(self, c):
        n = c.num_joints
        self.utime, self.sim_time, self.step, self.generation, self.num_joints = (
            c.utime, c.sim_time, c.step, c.generation, n)
        self.name = [_s(c.name[i].value) for i in range(n)]
        self.position, self.velocity, self.effort = (list(c.position[:n]), list(c.velocity[:n]),
                                                     list(c.effort[:n]))


class Reference(object):
    """A reference (reference_t's fields): utime, sim_time, step, generation, num_joints,
    lists name, r, rdot, rddot."""
    __slots__ = ("utime", "sim_time", "step", "generation", "num_joints", "name", "r", "rdot",
                 "rddot")

    def __init__(self, c):
        n = c.num_joints
        self.utime, self.sim_time, self.step, self.generation, self.num_joints = (
            c.utime, c.sim_time, c.step, c.generation, n)
        self.name = [_s(c.name[i].value) for i in range(n)]
        self.r, self.rdot, self.rddot = list(c.r[:n]), list(c.rdot[:n]), list(c.rddot[:n])


class Scene(object):
    """A copy of a scene (scene_t's fields, by their names) read from the library's."""

    def __init__(self, lib, sc):
        for k in ("model", "prefix", "integrator", "mode", "effects"):
            setattr(self, k, _s(getattr(lib, "lag_client_scene_" + k)(sc)))
        for k in ("dt", "control_period", "rate", "command_timeout", "generation", "utime"):
            setattr(self, k, getattr(lib, "lag_client_scene_" + k)(sc))
        self.num_params = lib.lag_client_scene_num_params(sc)
        self.param_name = [_s(lib.lag_client_scene_param_name(sc, i)) for i in range(self.num_params)]
        self.param_value = [lib.lag_client_scene_param_value(sc, i) for i in range(self.num_params)]
        self.num_joints = n = lib.lag_client_scene_num_joints(sc)
        self.joint_name = [_s(lib.lag_client_scene_joint_name(sc, i)) for i in range(n)]
        for k in ("actuated", "initial_q", "initial_qd", "limit_on", "limit_lower", "limit_upper"):
            f = getattr(lib, "lag_client_scene_" + k)
            setattr(self, k, [f(sc, i) for i in range(n)])


class Plant(object):
    """A plant heard on the bus: prefix, model, mode, run_state, host, url, sim_time."""

    def __init__(self, c):
        for k in ("prefix", "model", "mode", "run_state", "host", "url"):
            setattr(self, k, _s(getattr(c, k)))
        self.sim_time = c.sim_time


def pick_plant(url, model, wait_s):
    """(rc, Plant or None, message): the only plant (of model) on the bus (lag_client_pick_plant)."""
    p, err = _Plant(), ctypes.create_string_buffer(1200)
    rc = library().lag_client_pick_plant(_b(url), _b(model), wait_s, ctypes.byref(p),
                                         ctypes.sizeof(p), err, len(err))
    return rc, (Plant(p) if rc == OK else None), _s(err.value)


def locate(prefix, wait_s=LOCATE_WAIT_S):
    """(where, url): where the plant on prefix runs when no URL was given
    (lag_client_locate): LOCATE_HOST, url the one a host's directory on LCM's default bus
    names for it; LOCATE_HERE (a plant of that bus) or LOCATE_NONE (nothing heard within
    wait_s), url that bus's state URL. Raises ClientError for a prefix a plant cannot have
    or LCM failing."""
    url, err = ctypes.create_string_buffer(URL_LEN), ctypes.create_string_buffer(256)
    where = library().lag_client_locate(_b(prefix), wait_s, url, URL_LEN, err, len(err))
    if where < 0:
        raise ClientError(_s(err.value))
    return where, _s(url.value)


def plants_instead(url, prefix, wait_s):
    """What the bus has instead of a plant on prefix (lag_client_plants_instead)."""
    out = ctypes.create_string_buffer(1500)
    library().lag_client_plants_instead(_b(url), _b(prefix), wait_s, out, len(out))
    return _s(out.value)


class Client(object):
    """One lag_client: the plant with channel prefix `prefix` on `url`."""

    def __init__(self, prefix, url=None):
        self._lib = lib = library()
        err = ctypes.create_string_buffer(256)
        self._c = lib.lag_client_create(_b(url), _b(prefix), err, len(err))
        if not self._c:
            raise ClientError(_s(err.value))
        self._sc = lib.lag_client_scene_new()
        self.stopped = False  # the daemon's stop event came
        self._pending = None  # an exception raised in the event callback

        def on_event(ev, user):  # never unwinds through C: kept, raised after the call
            try:
                if ev.contents.kind == b"stop":
                    self.stopped = True
            except BaseException as e:
                self._pending = e

        self._on_event = _EVENT_FN(on_event)  # kept alive as long as the handle
        lib.lag_client_on_event(self._c, self._on_event, None)

    def _raise(self, rc):
        e, self._pending = self._pending, None
        if e is not None:
            raise e
        if rc < 0:
            raise ClientError(_s(self._lib.lag_client_errmsg(self._c)))
        return rc

    def wait_scene(self, timeout_s):
        """The scene (DESCRIBE sent until it comes) within timeout_s, or None."""
        rc = self._raise(self._lib.lag_client_wait_scene(self._c, timeout_s, self._sc))
        return Scene(self._lib, self._sc) if rc == OK else None

    def latest_scene(self):
        """The scene of the latest state's generation, or None."""
        if not self._lib.lag_client_latest_scene(self._c, self._sc):
            return None
        return Scene(self._lib, self._sc)

    def wait_state(self, timeout_s):
        """A state not yet returned (the newest), or None within timeout_s. Copies of the
        state answered last are answered by the library with the command sent for it."""
        st = _State()
        rc = self._raise(self._lib.lag_client_wait_state(self._c, timeout_s, ctypes.byref(st),
                                                         ctypes.sizeof(st)))
        return State(st) if rc == OK else None

    def latest_reference(self):
        r = _Reference()
        if not self._lib.lag_client_latest_reference(self._c, ctypes.byref(r), ctypes.sizeof(r)):
            return None
        return Reference(r)

    def send_command(self, sim_time, names, efforts):
        """Answers the state at sim_time (stamped with the latest state's generation)."""
        n = len(names)
        cn = (ctypes.c_char_p * max(n, 1))(*[x.encode() for x in names])
        ce = (ctypes.c_double * max(n, 1))(*efforts)
        self._raise(self._lib.lag_client_send_command(self._c, sim_time, n, cn, ce))

    def counters(self):
        k = _Counters()
        self._lib.lag_client_get_counters(self._c, ctypes.byref(k), ctypes.sizeof(k))
        return {name: getattr(k, name) for name, _ in _Counters._fields_}

    def now(self):
        return self._lib.lag_client_now()

    def close(self):
        if self._c:
            self._lib.lag_client_destroy(self._c)
            self._lib.lag_client_scene_free(self._sc)
            self._c = self._sc = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass
