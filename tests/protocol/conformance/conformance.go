// The conformance controller in Go, over the client library's C ABI (cgo over
// liblagsim_client.so.1): the conformance law, for tests/protocol/play.py.
//
//	conformance_go --prefix P --url URL [--timeout S]
//
// For each state the library returns: u = -(kp q + kd qd) on each actuated joint of the
// scene of that state's generation (lag_client_latest_scene; kp, kd: its parameters of
// those names), one line "conformance: law generation=G sim_time=T" on stdout before the
// command goes. It ends on the daemon's stop event (exit 0), or when no state came for
// --timeout wall seconds (default 60; exit 0); no scene within --timeout: exit 1
// (docs/protocol.md, "Checking a binding of your own").
package main

/*
#cgo pkg-config: lagsim-client
#include <stdint.h>
#include <stdlib.h>
#include "lagsim_client.h"

extern void goOnEvent(lag_client_event *ev, void *user); // defined in Go below
*/
import "C"

import (
	"flag"
	"fmt"
	"os"
	"runtime/cgo"
	"unsafe"
)

// goOnEvent: the handle's event callback; user points to C memory holding a cgo.Handle
// of the *bool it sets (C never holds a pointer to Go memory).
//
//export goOnEvent
func goOnEvent(ev *C.lag_client_event, user unsafe.Pointer) {
	if C.GoString(&ev.kind[0]) == "stop" {
		*cgo.Handle(*(*C.uintptr_t)(user)).Value().(*bool) = true
	}
}

func cstr(s string) *C.char { return C.CString(s) } // freed by the caller

func main() {
	prefix := flag.String("prefix", "CONFORMANCE", "the plant's channel prefix")
	url := flag.String("url", "", "the plant's LCM URL")
	timeout := flag.Float64("timeout", 60, "wall s without a scene or a state")
	flag.Parse()
	if C.lag_client_abi() != C.LAGSIM_CLIENT_ABI {
		fmt.Fprintf(os.Stderr, "conformance_go: liblagsim_client has ABI %d, not %d\n",
			int(C.lag_client_abi()), C.LAGSIM_CLIENT_ABI)
		os.Exit(1)
	}
	var cerr [256]C.char
	if *url == "" { // where a host's directory on the default bus says the plant runs
		var found [C.LAG_CLIENT_URL_LEN]C.char
		cp := cstr(*prefix)
		if C.lag_client_locate(cp, C.LAG_CLIENT_LOCATE_WAIT_S, &found[0], C.size_t(len(found)),
			nil, 0) == C.LAG_CLIENT_LOCATE_HOST {
			*url = C.GoString(&found[0])
		}
		C.free(unsafe.Pointer(cp))
	}
	curl, cprefix := cstr(*url), cstr(*prefix)
	c := C.lag_client_create(curl, cprefix, &cerr[0], C.size_t(len(cerr)))
	C.free(unsafe.Pointer(curl))
	C.free(unsafe.Pointer(cprefix))
	if c == nil {
		fmt.Fprintf(os.Stderr, "conformance_go: %s\n", C.GoString(&cerr[0]))
		os.Exit(1)
	}
	stopped := false
	h := cgo.NewHandle(&stopped) // a Go value C may hold: its handle, never its pointer
	user := C.malloc(C.size_t(unsafe.Sizeof(C.uintptr_t(0))))
	*(*C.uintptr_t)(user) = C.uintptr_t(h)
	C.lag_client_on_event(c, C.lag_client_event_fn(C.goOnEvent), user)
	if C.lag_client_wait_scene(c, C.double(*timeout), nil) != C.LAG_CLIENT_OK {
		fmt.Fprintf(os.Stderr, "conformance_go: %s\n", C.GoString(C.lag_client_errmsg(c)))
		C.lag_client_destroy(c)
		os.Exit(1)
	}
	laws := 0
	heard := C.lag_client_now()
	sc := C.lag_client_scene_new() // the scene of a state's generation
	kp, kd := cstr("kp"), cstr("kd")
	names := (**C.char)(C.malloc(C.size_t(C.LAG_CLIENT_MAX_JOINTS) * C.size_t(unsafe.Sizeof((*C.char)(nil)))))
	nameAt := unsafe.Slice(names, C.LAG_CLIENT_MAX_JOINTS)
	var u [C.LAG_CLIENT_MAX_JOINTS]C.double
	for !stopped && float64(C.lag_client_now()-heard) < *timeout {
		var st C.lag_client_state
		rc := C.lag_client_wait_state(c, 0.1, &st, C.size_t(unsafe.Sizeof(st)))
		if rc == C.LAG_CLIENT_TIMEOUT {
			continue
		}
		if rc != C.LAG_CLIENT_OK {
			break
		}
		heard = C.lag_client_now()
		if sc == nil || !C.lag_client_latest_scene(c, sc) {
			break
		}
		// the law: names point into the scene (owned by it, valid until it is filled again)
		p, d := C.lag_client_scene_param(sc, kp), C.lag_client_scene_param(sc, kd)
		n, ok := 0, true
		for j := C.int(0); j < C.lag_client_scene_num_joints(sc); j++ {
			if !C.lag_client_scene_actuated(sc, j) {
				continue
			}
			jn := C.lag_client_scene_joint_name(sc, j)
			i := C.lag_client_state_joint(&st, jn)
			if i < 0 {
				ok = false
				break
			}
			nameAt[n] = jn
			u[n] = -(C.double(p*st.position[i]) + C.double(d*st.velocity[i])) // rounded products: C's
			n++
		}
		if !ok {
			continue
		}
		laws++
		fmt.Printf("conformance: law generation=%d sim_time=%.17g\n", int64(st.generation), float64(st.sim_time))
		C.lag_client_send_command(c, st.sim_time, C.int(n), names, &u[0])
	}
	var k C.lag_client_counters
	C.lag_client_get_counters(c, &k, C.size_t(unsafe.Sizeof(k)))
	end := "silence"
	if stopped {
		end = "stop"
	}
	fmt.Printf("conformance_go: summary end=%s laws=%d held=%d describes=%d dropped=%d repeats=%d\n",
		end, laws, int64(k.held), int64(k.describes), int64(k.dropped), int64(k.repeats))
	C.free(unsafe.Pointer(names))
	C.free(unsafe.Pointer(kp))
	C.free(unsafe.Pointer(kd))
	C.lag_client_scene_free(sc)
	C.lag_client_destroy(c)
	C.free(user)
	h.Delete()
}
