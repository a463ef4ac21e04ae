"""LCM from Python with the standard library only: ctypes over liblcm.so.1.

Debian has no Python LCM module, but the C library is enough. Messages are encoded and
decoded by the classes `lcm-gen --python` makes (they import only `struct`); the build
puts them and this module in <build>/python, `cmake --install` in Python's site
directory, so with PYTHONPATH=<build>/python (or after installing) this works anywhere:

    from lagsim_lcm import LCM
    from lagsim import joint_state_t
    lc = LCM()                     # LCM's default URL (honours LCM_DEFAULT_URL)
    lc.subscribe("DIPC_STATE", lambda channel, data: print(joint_state_t.decode(data)))
    lc.handle_timeout(100)         # ms; True if a message was handled, False on timeout

A lagsim plant listens for commands on its own URL, the next port (plant_urls):

    from lagsim_lcm import LCM, plant_urls
    state_url, command_url = plant_urls()      # from the daemon's lcm.url (None: default)
    lc, lc_cmd = LCM(state_url), LCM(command_url)
    lc_cmd.publish("DIPC_COMMAND", cmd.encode())

The methods follow LCM's own Python binding:
- subscribe(channel, handler) takes a POSIX extended regular expression, anchored at both
  ends, like every LCM binding ("DIPC_.*" receives every channel of the prefix; a plain
  channel name matches itself). Returns a subscription for unsubscribe().
- An exception raised by a handler stops that dispatch and is raised again by the
  handle() or handle_timeout() call that ran the handler, with its traceback: it never
  unwinds through C and is never swallowed.
- handle() blocks until one message has been handled; handle_timeout(ms) waits at most
  ms milliseconds; fileno() gives the socket for select()/poll(). A signal that
  interrupts the wait is no error: its Python handler runs and handle_timeout() returns
  False (handle() waits on), so a loop that checks a flag set by a handler of SIGINT or
  SIGTERM ends cleanly.

Not thread-safe, like lcm_t itself: use one LCM per thread.
"""
import ctypes
import ctypes.util
import errno

__all__ = ["LCM", "LCMError", "plant_urls"]


class LCMError(RuntimeError):
    pass


def plant_urls(url=None):
    """The two LCM URLs of a lagsim plant whose lcm.url is `url` (None or "": the
    environment's LCM_DEFAULT_URL, else LCM's default): (state URL, command URL).

    The daemon publishes <PREFIX>_STATE, _STATUS, _EVENT and _SCENE on the state URL (the
    URL itself) and listens for <PREFIX>_COMMAND and _CONTROL on the command URL: the
    same group and options on the next port. memq:// is both. The rule is the C library's
    own (lag_client_plant_urls, through lagsim_client.py), checked against the cases of
    tests/net/plant_urls.txt. Raises ValueError for a URL a plant cannot have."""
    from lagsim_client import plant_urls as rule
    return rule(url)


class _RecvBuf(ctypes.Structure):
    # struct _lcm_recv_buf_t from <lcm/lcm.h> (LCM 1.3)
    _fields_ = [
        ("data", ctypes.c_void_p),
        ("data_size", ctypes.c_uint32),
        ("recv_utime", ctypes.c_int64),
        ("lcm", ctypes.c_void_p),
    ]


# void (*lcm_msg_handler_t)(const lcm_recv_buf_t *rbuf, const char *channel, void *user)
_HANDLER = ctypes.CFUNCTYPE(None, ctypes.POINTER(_RecvBuf), ctypes.c_char_p, ctypes.c_void_p)


def _load():
    names = ["liblcm.so.1", ctypes.util.find_library("lcm") or "liblcm.so"]
    last = None
    for name in names:
        try:
            lib = ctypes.CDLL(name, use_errno=True)
            break
        except OSError as e:  # try the next name
            last = e
    else:
        raise LCMError("cannot load liblcm.so.1 (apt-get install liblcm1): %s" % last)
    lib.lcm_create.argtypes = [ctypes.c_char_p]
    lib.lcm_create.restype = ctypes.c_void_p
    lib.lcm_destroy.argtypes = [ctypes.c_void_p]
    lib.lcm_destroy.restype = None
    lib.lcm_get_fileno.argtypes = [ctypes.c_void_p]
    lib.lcm_get_fileno.restype = ctypes.c_int
    lib.lcm_subscribe.argtypes = [ctypes.c_void_p, ctypes.c_char_p, _HANDLER, ctypes.c_void_p]
    lib.lcm_subscribe.restype = ctypes.c_void_p
    lib.lcm_unsubscribe.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    lib.lcm_unsubscribe.restype = ctypes.c_int
    lib.lcm_publish.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_void_p,
                                ctypes.c_uint]
    lib.lcm_publish.restype = ctypes.c_int
    lib.lcm_handle.argtypes = [ctypes.c_void_p]
    lib.lcm_handle.restype = ctypes.c_int
    lib.lcm_handle_timeout.argtypes = [ctypes.c_void_p, ctypes.c_int]
    lib.lcm_handle_timeout.restype = ctypes.c_int
    return lib


_lib = None


class LCM(object):
    """One lcm_t. url None or "" = LCM's default (LCM_DEFAULT_URL or udpm ttl=0)."""

    def __init__(self, url=None):
        global _lib
        if _lib is None:
            _lib = _load()
        self._lib = _lib
        self._lcm = _lib.lcm_create(url.encode() if url else None)
        if not self._lcm:
            raise LCMError("lcm_create(%r) failed" % (url or "default"))
        # ctypes callbacks must outlive the subscription: keep every one here
        self._subs = {}
        self._pending = None  # exception raised by a handler, raised again by handle*()

    def subscribe(self, channel, handler):
        """Calls handler(channel_str, payload_bytes) for each message whose channel
        matches the regular expression `channel` (anchored, as in LCM)."""

        def trampoline(rbuf, chan, user):
            if self._pending is not None:  # an earlier handler failed: stop this dispatch
                return
            try:
                data = ctypes.string_at(rbuf.contents.data, rbuf.contents.data_size)
                handler(chan.decode("utf-8", "replace"), data)
            except BaseException as e:  # never unwind through C: kept, raised by handle*()
                self._pending = e

        cb = _HANDLER(trampoline)
        sub = self._lib.lcm_subscribe(self._lcm, channel.encode(), cb, None)
        if not sub:
            raise LCMError("lcm_subscribe(%r) failed" % channel)
        self._subs[sub] = cb
        return sub

    def unsubscribe(self, sub):
        if sub not in self._subs:
            raise LCMError("not a subscription of this LCM")
        if self._lib.lcm_unsubscribe(self._lcm, sub) != 0:
            raise LCMError("lcm_unsubscribe failed")
        del self._subs[sub]

    def publish(self, channel, data):
        buf = bytes(data)
        rc = self._lib.lcm_publish(self._lcm, channel.encode(), buf, len(buf))
        if rc != 0:
            raise LCMError("lcm_publish(%r) failed" % channel)

    def _raise_pending(self):
        e, self._pending = self._pending, None
        if e is not None:
            raise e

    def handle(self):
        """Waits for one message and runs its handlers. A signal's handler runs (a
        KeyboardInterrupt it raises reaches the caller) and the wait goes on, as
        Python's own blocking calls do (PEP 475)."""
        while True:
            ctypes.set_errno(0)
            rc = self._lib.lcm_handle(self._lcm)
            self._raise_pending()
            if rc == 0:
                return
            if ctypes.get_errno() != errno.EINTR:
                raise LCMError("lcm_handle failed")

    def handle_timeout(self, timeout_ms):
        """Handles at most one message, waiting up to timeout_ms milliseconds.
        True if a message was handled, False on timeout or when a signal ended the wait
        (its Python handler runs as this returns: a controller's SIGTERM handler ends its
        run instead of an error), as the C client's lag_client_handle."""
        ctypes.set_errno(0)
        rc = self._lib.lcm_handle_timeout(self._lcm, int(max(0, timeout_ms)))
        self._raise_pending()
        if rc < 0:
            if ctypes.get_errno() == errno.EINTR:
                return False
            raise LCMError("lcm_handle_timeout failed")
        return rc > 0

    def fileno(self):
        return self._lib.lcm_get_fileno(self._lcm)

    def close(self):
        if self._lcm:
            for sub in list(self._subs):
                self._lib.lcm_unsubscribe(self._lcm, sub)
            self._lib.lcm_destroy(self._lcm)
            self._lcm = None
            self._subs = {}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass
