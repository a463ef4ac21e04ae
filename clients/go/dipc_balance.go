// dipc_balance.go: balances the double inverted pendulum on a cart (DIPC) upright with a
// given LQR gain, in Go, through the client library's C ABI alone (cgo over
// liblagsim_client.so.1: docs/clients.md, "In Go, and any language with a C FFI").
//
//	PKG_CONFIG_PATH=<build>/pkgconfig go build -o dipc_balance_go dipc_balance.go
//	./dipc_balance_go --k k0,...,k5 [--prefix P] [--url URL] [--duration S] [--timeout S]
//	                  [--trace FILE] [-q]
//
// The law is the C example's (dipc_lqr --k): u = -K x on theta0 with
// x = (theta0, theta1, theta2, theta0_dot, theta1_dot, theta2_dot), computed as
// 0 - k0 x0 - k1 x1 - ... - k5 x5 in that order, every product rounded to a double before
// it is subtracted (float64(...): the Go spec lets a compiler fuse a*b+c into one rounding
// otherwise, as it does on arm64), so that it answers every state with C's bits. The gain
// is given (dipc_lqr and lqr_balance print the LQR gain for a running plant; Go has no
// LAPACK in its standard library). The library does the protocol: the command URL, the
// scene (DESCRIBE until it comes), each state once with its copies answered, the scene
// rule, the generation on every command, every message decoded whole.
//
// The run ends on the daemon's stop event, after --timeout wall seconds without a state,
// after --duration s of sim time from the first state, or on SIGINT/SIGTERM; then one
// summary line, as the other examples print it. Exit status: 0 done, 1 no plant or a
// library that cannot run this program, 2 bad usage.
package main

/*
#cgo pkg-config: lagsim-client
#include <stdlib.h>
#include "lagsim_client.h"

extern void goOnEvent(lag_client_event *ev, void *user); // defined in Go below
*/
import "C"

import (
	"flag"
	"fmt"
	"math"
	"os"
	"os/signal"
	"strconv"
	"strings"
	"sync/atomic"
	"syscall"
	"unsafe"
)

const name = "dipc_balance.go"

var stopped atomic.Bool // the daemon's stop event came (set by goOnEvent)

//export goOnEvent
func goOnEvent(ev *C.lag_client_event, user unsafe.Pointer) {
	// runs inside lag_client_wait_state, in this goroutine's thread; ev is valid only
	// during the call: copy what is kept
	if C.GoString(&ev.kind[0]) == "stop" {
		stopped.Store(true)
	}
}

func fail(code int, format string, args ...interface{}) {
	fmt.Fprintf(os.Stderr, name+": "+format+"\n", args...)
	os.Exit(code)
}

// checkLibrary refuses a library this program cannot run with: another ABI (another
// SONAME: the loader would not have found it, unless renamed) or an older release than
// the header it was compiled against (a function it calls may be missing).
func checkLibrary() {
	if abi := int(C.lag_client_abi()); abi != C.LAGSIM_CLIENT_ABI {
		fail(1, "liblagsim_client has ABI %d, this program was built for ABI %d", abi, C.LAGSIM_CLIENT_ABI)
	}
	if v := int(C.lag_client_version()); v < C.LAGSIM_VERSION_NUMBER {
		fail(1, "liblagsim_client is version %d, older than the header this program was built with (%d)",
			v, C.LAGSIM_VERSION_NUMBER)
	}
}

func parseGain(s string) ([6]float64, error) {
	var k [6]float64
	f := strings.Split(s, ",")
	if len(f) != 6 {
		return k, fmt.Errorf("--k wants 6 comma-separated numbers, got %q", s)
	}
	for i, v := range f {
		x, err := strconv.ParseFloat(strings.TrimSpace(v), 64) // correctly rounded, as strtod
		if err != nil || math.IsInf(x, 0) || math.IsNaN(x) {
			return k, fmt.Errorf("--k wants 6 finite numbers, got %q", v)
		}
		k[i] = x
	}
	return k, nil
}

func main() {
	prefix := flag.String("prefix", "DIPC", "the plant's channel prefix")
	url := flag.String("url", "", "the plant's LCM URL, its lcm.url (default: LCM's default, LCM_DEFAULT_URL); commands go to the next port")
	gain := flag.String("k", "", "the gain k0,...,k5 of u = -K x (required)")
	duration := flag.Float64("duration", 0, "stop after S s of sim time from the first state (0: until the daemon stops)")
	timeout := flag.Float64("timeout", 5, "wall s without a scene, or without a state once running, before ending")
	tracePath := flag.String("trace", "", "write each answered state and the effort sent to this file")
	quiet := flag.Bool("q", false, "quiet: summary only")
	flag.Parse()
	if flag.NArg() > 0 || *gain == "" || !(*timeout > 0) || !(*duration >= 0) {
		flag.Usage()
		os.Exit(2)
	}
	K, err := parseGain(*gain)
	if err != nil {
		fail(2, "%v", err)
	}
	checkLibrary()

	var trace *os.File
	if *tracePath != "" {
		if trace, err = os.Create(*tracePath); err != nil {
			fail(1, "--trace: %v", err)
		}
		defer trace.Close()
	}
	sig := make(chan os.Signal, 1)
	signal.Notify(sig, syscall.SIGINT, syscall.SIGTERM)

	// the handle: C memory, freed by lag_client_destroy; the strings passed are copied
	var cerr [256]C.char
	curl, cprefix := C.CString(*url), C.CString(*prefix)
	c := C.lag_client_create(curl, cprefix, &cerr[0], C.size_t(len(cerr)))
	C.free(unsafe.Pointer(curl))
	C.free(unsafe.Pointer(cprefix))
	if c == nil {
		fail(1, "%s", C.GoString(&cerr[0]))
	}
	defer C.lag_client_destroy(c)
	C.lag_client_on_event(c, C.lag_client_event_fn(C.goOnEvent), nil)

	sc := C.lag_client_scene_new() // the scene: opaque, read through accessors
	defer C.lag_client_scene_free(sc)
	fmt.Printf("%s: waiting for the scene description on %s_SCENE\n", name, *prefix)
	if !waitScene(c, sc, *url, *prefix, *timeout, sig) {
		summary(c, "signal", 0, "") // SIGINT or SIGTERM while waiting: a run that ended
		return
	}
	if model := C.GoString(C.lag_client_scene_model(sc)); model != "dipc" {
		fail(1, "prefix %s runs model '%s', not dipc", *prefix, model)
	}
	if !*quiet {
		fmt.Printf("%s: applying the given gain: u = -K x on theta0, K = %v\n", name, K)
	}

	theta0 := C.CString("theta0") // the name commanded, in C memory for the whole run
	defer C.free(unsafe.Pointer(theta0))
	names := [1]*C.char{theta0}
	joints := [3]string{"theta0", "theta1", "theta2"}

	var st C.lag_client_state
	var states int64
	tFirst, tLast, tReport := math.NaN(), math.NaN(), math.Inf(-1)
	var maxTheta, endTheta [3]float64
	maxU := 0.0
	end := ""
	heard := float64(C.lag_client_now())
	for end == "" {
		select {
		case <-sig:
			end = "signal"
			continue
		default:
		}
		if states > 0 && *duration > 0 &&
			tLast-tFirst >= *duration-0.5*float64(C.lag_client_scene_control_period(sc)) {
			end = "duration"
			continue
		}
		// the next state not yet returned; a copy of one is answered by the library
		rc := C.lag_client_wait_state(c, 0.05, &st, C.size_t(unsafe.Sizeof(st)))
		if rc != C.LAG_CLIENT_OK {
			switch {
			case rc < 0:
				fail(1, "%s", C.GoString(C.lag_client_errmsg(c)))
			case stopped.Load():
				end = "stop"
			case float64(C.lag_client_now())-heard > *timeout:
				end = "silence"
			}
			continue
		}
		heard = float64(C.lag_client_now())
		var x [6]float64
		missing := false
		for k, j := range joints {
			cj := C.CString(j)
			i := C.lag_client_state_joint(&st, cj)
			C.free(unsafe.Pointer(cj))
			if i < 0 {
				missing = true
				break
			}
			x[k] = float64(st.position[i])
			x[3+k] = float64(st.velocity[i])
		}
		if missing {
			continue
		}
		u := 0.0
		for k := 0; k < 6; k++ {
			u -= float64(K[k] * x[k]) // rounded product, then the difference: C's order
		}
		if math.IsNaN(u) || math.IsInf(u, 0) {
			u = 0 // the library refuses a non-finite effort: send 0, as the C examples
		}
		cu := C.double(u)
		if rc := C.lag_client_send_command(c, st.sim_time, 1, &names[0], &cu); rc != C.LAG_CLIENT_OK {
			fail(1, "%s", C.GoString(C.lag_client_errmsg(c)))
		}
		t := float64(st.sim_time)
		if trace != nil { // sim time, positions, velocities, effort: %.17g reads back exactly
			n := int(st.num_joints)
			fmt.Fprintf(trace, "%.17g", t)
			for i := 0; i < n; i++ {
				fmt.Fprintf(trace, " %.17g", float64(st.position[i]))
			}
			for i := 0; i < n; i++ {
				fmt.Fprintf(trace, " %.17g", float64(st.velocity[i]))
			}
			fmt.Fprintf(trace, " %.17g\n", u)
		}
		if states == 0 {
			tFirst = t
		}
		states++
		tLast = t
		for k := 0; k < 3; k++ {
			maxTheta[k] = math.Max(maxTheta[k], math.Abs(x[k]))
		}
		maxU = math.Max(maxU, math.Abs(u))
		copy(endTheta[:], x[:3])
		if !*quiet && t-tReport >= 1.0 {
			tReport = t
			fmt.Printf("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f\n", t, x[0], x[1], x[2], u)
		}
	}
	summary(c, end, states, fmt.Sprintf("t_first=%.6f t_last=%.6f max_abs_theta0=%.6g "+
		"max_abs_theta1=%.6g max_abs_theta2=%.6g max_abs_effort=%.6g end_theta1=%.3g end_theta2=%.3g",
		tFirst, tLast, maxTheta[0], maxTheta[1], maxTheta[2], maxU, endTheta[1], endTheta[2]))
}

// waitScene waits up to timeout s for the scene (the library sends DESCRIBE every 0.25 s
// until it comes), in slices that let a signal end the wait: false on a signal. No scene:
// what the bus has instead (a misspelt --prefix?), exit 1.
func waitScene(c *C.lag_client, sc *C.lag_client_scene, url, prefix string, timeout float64,
	sig chan os.Signal) bool {
	deadline := float64(C.lag_client_now()) + timeout
	for {
		select {
		case <-sig:
			return false
		default:
		}
		left := deadline - float64(C.lag_client_now())
		rc := C.lag_client_wait_scene(c, C.double(math.Min(left, 0.25)), sc)
		if rc == C.LAG_CLIENT_OK {
			return true
		}
		if rc < 0 {
			fail(1, "%s", C.GoString(C.lag_client_errmsg(c)))
		}
		if left <= 0.25 {
			var instead [1500]C.char
			curl, cprefix := C.CString(url), C.CString(prefix)
			C.lag_client_plants_instead(curl, cprefix, 1.0, &instead[0], C.size_t(len(instead)))
			C.free(unsafe.Pointer(curl))
			C.free(unsafe.Pointer(cprefix))
			fail(1, "no scene description on %s_SCENE within %g s: %s", prefix, timeout,
				C.GoString(&instead[0]))
		}
	}
}

// summary prints the examples' summary line: how the run ended, its states, the law's
// figures, and the library's counts of dropped messages and copies answered again.
func summary(c *C.lag_client, end string, states int64, figures string) {
	var cnt C.lag_client_counters
	C.lag_client_get_counters(c, &cnt, C.size_t(unsafe.Sizeof(cnt)))
	if figures != "" {
		figures += " "
	}
	fmt.Printf("%s: summary end=%s states=%d %sdropped=%d repeats=%d\n", name, end, states,
		figures, int64(cnt.dropped), int64(cnt.repeats))
}
