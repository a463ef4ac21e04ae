// dipc_balance.go: balances the double inverted pendulum on a cart (DIPC) upright with LQR,
// in Go, through the client library's C ABI alone (cgo over liblagsim_client.so.1:
// docs/clients.md, "In Go, and any language with a C FFI").
//
//	PKG_CONFIG_PATH=<build>/pkgconfig go build -o dipc_balance_go dipc_balance.go
//	./dipc_balance_go [--prefix P] [--url URL] [--duration S] [--timeout S] [--q w0,...,w5]
//	                  [--r R] [--k k0,...,k5] [--trace FILE] [-q]
//
// The gain is designed from the scene's parameters as the Python, Lua and Java examples
// design it, line for line (docs/clients.md: linearized about upright from T and U, a
// zero-order hold over the control period by a scaled Taylor series, the discrete LQR by
// the structure-preserving doubling algorithm), so it is theirs to the last bit; --k
// applies a given gain instead. The law is dipc_lqr's: u = -K x on theta0 with
// x = (theta0, theta1, theta2, theta0_dot, theta1_dot, theta2_dot), computed as
// 0 - k0 x0 - k1 x1 - ... - k5 x5 in that order. Every product is rounded to a double
// before it is added (float64(a*b): the Go spec lets a compiler fuse a*b+c into one
// rounding otherwise, as it does on arm64), so the Go program answers with C's bits.
// The library does the protocol: the command URL, the scene (DESCRIBE until it comes),
// each state once with its copies answered, the scene rule, the generation on every
// command, every message decoded whole.
//
// The run ends on the daemon's stop event, after --timeout wall seconds without a state,
// after --duration s of sim time from the first state, or on SIGINT/SIGTERM; then one
// summary line with the keys of the other examples. Exit status: 0 done, 1 no plant, a
// gain that does not stabilize or a library this program cannot use, 2 bad usage.
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

const name = "dipc_balance_go" // the program built from this file: its messages' name
const N = 6                    // states

type matrix [][]float64

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

// checkLibrary refuses a library this program cannot run with: another ABI, or an older
// release than the header it was compiled against (a function it calls may be missing).
func checkLibrary() {
	if abi := int(C.lag_client_abi()); abi != C.LAGSIM_CLIENT_ABI {
		fail(1, "liblagsim_client has ABI %d, this program was built for ABI %d", abi, C.LAGSIM_CLIENT_ABI)
	}
	if v := int(C.lag_client_version()); v < C.LAGSIM_VERSION_NUMBER {
		fail(1, "liblagsim_client is version %d, older than the header this program was built with (%d)",
			v, C.LAGSIM_VERSION_NUMBER)
	}
}

// parseList reads N comma-separated finite numbers (correctly rounded, as strtod).
func parseList(s, what string) []float64 {
	f := strings.Split(s, ",")
	v := make([]float64, 0, N)
	for _, x := range f {
		y, err := strconv.ParseFloat(strings.TrimSpace(x), 64)
		if err != nil || math.IsInf(y, 0) || math.IsNaN(y) {
			break
		}
		v = append(v, y)
	}
	if len(f) != N || len(v) != N {
		fail(2, "%s wants %d comma-separated numbers", what, N)
	}
	return v
}

// ---------------------------------------------------------------- the design

func zeros(r, c int) matrix {
	m := make(matrix, r)
	for i := range m {
		m[i] = make([]float64, c)
	}
	return m
}

func eye(n int) matrix {
	m := zeros(n, n)
	for i := 0; i < n; i++ {
		m[i][i] = 1
	}
	return m
}

// matmul: each element 0 + a0 b0 + a1 b1 + ..., left to right.
func matmul(a, b matrix) matrix {
	m := zeros(len(a), len(b[0]))
	for i := range a {
		for j := range b[0] {
			s := 0.0
			for k := range b {
				s += float64(a[i][k] * b[k][j])
			}
			m[i][j] = s
		}
	}
	return m
}

func transpose(a matrix) matrix {
	m := zeros(len(a[0]), len(a))
	for i := range a {
		for j := range a[0] {
			m[j][i] = a[i][j]
		}
	}
	return m
}

// inverse: Gauss-Jordan with partial pivoting (the first largest pivot).
func inverse(a matrix) matrix {
	n := len(a)
	m := zeros(n, 2*n)
	for i := 0; i < n; i++ {
		copy(m[i], a[i])
		m[i][n+i] = 1
	}
	for c := 0; c < n; c++ {
		p := c
		for r := c + 1; r < n; r++ {
			if math.Abs(m[r][c]) > math.Abs(m[p][c]) {
				p = r
			}
		}
		if m[p][c] == 0 {
			fail(1, "the design met a singular matrix")
		}
		m[c], m[p] = m[p], m[c]
		piv := m[c][c]
		for j := range m[c] {
			m[c][j] /= piv
		}
		for r := 0; r < n; r++ {
			if r != c && m[r][c] != 0 {
				f := m[r][c]
				for j := range m[r] {
					m[r][j] -= float64(f * m[c][j])
				}
			}
		}
	}
	out := zeros(n, n)
	for i := range out {
		copy(out[i], m[i][n:])
	}
	return out
}

// expm: exp(A) by scaling so that ||A||_1 / 2^s <= 0.5, Taylor to order 20, s squarings.
func expm(a matrix) matrix {
	n := len(a)
	norm := 0.0
	for j := 0; j < n; j++ {
		col := 0.0
		for i := 0; i < n; i++ {
			col += math.Abs(a[i][j])
		}
		norm = math.Max(norm, col)
	}
	s := 0
	for norm > 0.5 {
		norm /= 2
		s++
	}
	as := zeros(n, n)
	for i := range a {
		for j := range a[i] {
			as[i][j] = a[i][j] / math.Pow(2, float64(s))
		}
	}
	e, t := eye(n), eye(n)
	for k := 1; k <= 20; k++ {
		t = matmul(t, as)
		for i := range t {
			for j := range t[i] {
				t[i][j] /= float64(k)
				e[i][j] += t[i][j]
			}
		}
	}
	for ; s > 0; s-- {
		e = matmul(e, e)
	}
	return e
}

// linearize: A, B of the DIPC about upright from T and U (docs/clients.md).
func linearize(p map[string]float64) (matrix, matrix) {
	m0, m1, m2, l1, l2, I1, I2, g := p["m0"], p["m1"], p["m2"], p["l1"], p["l2"], p["I1"], p["I2"], p["g"]
	a := float64(m1*l1)/2 + float64(m2*l1)
	M0 := matrix{
		{m0 + m1 + m2, a, float64(m2*l2) / 2},
		{a, float64(float64(m1*l1)*l1)/4 + float64(float64(m2*l1)*l1) + I1, float64(float64(m2*l1)*l2) / 2},
		{float64(m2*l2) / 2, float64(float64(m2*l1)*l2) / 2, float64(float64(m2*l2)*l2)/4 + I2}}
	G := []float64{0, -a * g, float64(float64(-m2*l2)*g) / 2}
	Mi := inverse(M0)
	A, B := zeros(N, N), zeros(N, 1)
	for i := 0; i < 3; i++ {
		A[i][3+i] = 1
		for j := 0; j < 3; j++ {
			A[3+i][j] = -Mi[i][j] * G[j]
		}
		B[3+i][0] = Mi[i][0]
	}
	return A, B
}

// c2d: zero-order hold, Ad = e^(A h), Bd = int_0^h e^(A s) ds B.
func c2d(A, B matrix, h float64) (matrix, matrix) {
	Z := zeros(N+1, N+1)
	for i := 0; i < N; i++ {
		for j := 0; j < N; j++ {
			Z[i][j] = A[i][j] * h
		}
		Z[i][N] = B[i][0] * h
	}
	E := expm(Z)
	Ad, Bd := zeros(N, N), zeros(N, 1)
	for i := 0; i < N; i++ {
		copy(Ad[i], E[i][:N])
		Bd[i][0] = E[i][N]
	}
	return Ad, Bd
}

// dare: X of X = A'XA - A'XB (R + B'XB)^-1 B'XA + Q by doubling (scalar input).
func dare(A, B, Q matrix, R float64) matrix {
	Ak, Gk, Hk := A, zeros(N, N), Q
	for i := 0; i < N; i++ {
		for j := 0; j < N; j++ {
			Gk[i][j] = float64(B[i][0]*B[j][0]) / R
		}
	}
	for it := 0; it < 100; it++ {
		W := zeros(N, N)
		for i := 0; i < N; i++ {
			for j := 0; j < N; j++ {
				s := 0.0
				for k := 0; k < N; k++ {
					s += float64(Gk[i][k] * Hk[k][j])
				}
				W[i][j] = eye(N)[i][j] + s
			}
		}
		W = inverse(W)
		AW := matmul(Ak, W)
		An := matmul(AW, Ak)
		Gn, Hn := matmul(matmul(AW, Gk), transpose(Ak)), matmul(matmul(transpose(Ak), Hk), matmul(W, Ak))
		diff, size := 0.0, 0.0
		for i := 0; i < N; i++ {
			for j := 0; j < N; j++ {
				Gn[i][j] = Gk[i][j] + Gn[i][j]
				Hn[i][j] = Hk[i][j] + Hn[i][j]
				diff = math.Max(diff, math.Abs(Hn[i][j]-Hk[i][j]))
				size = math.Max(size, math.Abs(Hn[i][j]))
			}
		}
		Ak, Gk, Hk = An, Gn, Hn
		if diff <= 1e-14*size {
			return Hk
		}
	}
	fail(1, "the Riccati doubling did not converge")
	return nil
}

// design: the discrete LQR of the zero-order-hold plant at h, cost (Q h, R h).
func design(p map[string]float64, h float64, qw []float64, r float64) (matrix, matrix, []float64) {
	A, B := linearize(p)
	Ad, Bd := c2d(A, B, h)
	Qd := zeros(N, N)
	for i := 0; i < N; i++ {
		Qd[i][i] = qw[i] * h
	}
	X := dare(Ad, Bd, Qd, r*h)
	XB := matmul(X, Bd)
	den := 0.0
	for i := 0; i < N; i++ {
		den += float64(Bd[i][0] * XB[i][0])
	}
	den = r*h + den
	row := matmul(transpose(XB), Ad)[0]
	K := make([]float64, N)
	for j := range K {
		K[j] = row[j] / den
	}
	return Ad, Bd, K
}

func closedLoop(Ad, Bd matrix, K []float64) matrix {
	m := zeros(N, N)
	for i := 0; i < N; i++ {
		for j := 0; j < N; j++ {
			m[i][j] = Ad[i][j] - float64(Bd[i][0]*K[j])
		}
	}
	return m
}

// stabilizes: powers of the sampled closed loop shrink (P^4096 below 1e-3).
func stabilizes(Acl matrix) bool {
	P := Acl
	for i := 0; i < 12; i++ {
		P = matmul(P, P)
	}
	mx := 0.0
	for _, row := range P {
		for _, x := range row {
			mx = math.Max(mx, math.Abs(x))
		}
	}
	return mx < 1e-3
}

// predict: the linearized sampled loop from the first state answered, as many periods.
func predict(Acl matrix, x0 []float64, states int64) [3]float64 {
	var pred [3]float64
	if x0 == nil {
		return pred
	}
	xl := append([]float64(nil), x0...)
	for n := int64(0); n < states; n++ {
		for k := 0; k < 3; k++ {
			pred[k] = math.Max(pred[k], math.Abs(xl[k]))
		}
		xn := make([]float64, N)
		for i := 0; i < N; i++ {
			s := 0.0
			for j := 0; j < N; j++ {
				s += float64(Acl[i][j] * xl[j])
			}
			xn[i] = s
		}
		xl = xn
	}
	return pred
}

func joinG(v []float64) string {
	s := make([]string, len(v))
	for i, x := range v {
		s[i] = strconv.FormatFloat(x, 'g', 17, 64)
	}
	return strings.Join(s, ", ")
}

// ---------------------------------------------------------------- the run

type options struct {
	prefix, url, gain, qweights, trace string
	duration, timeout, r               float64
	quiet                              bool
}

func parseOptions() options {
	var o options
	flag.StringVar(&o.prefix, "prefix", "DIPC", "the plant's channel prefix")
	flag.StringVar(&o.url, "url", "", "the plant's LCM URL, its lcm.url (default: the URL a host's directory on LCM's default bus names for --prefix, else LCM's default, LCM_DEFAULT_URL); commands go to the next port")
	flag.Float64Var(&o.duration, "duration", 0, "stop after S s of sim time from the first state (0: until the daemon stops)")
	flag.Float64Var(&o.timeout, "timeout", 5, "wall s without a scene, or without a state once running, before ending")
	flag.StringVar(&o.qweights, "weights", "5,50,50,20,700,700", "state weights")
	flag.Float64Var(&o.r, "r", 1, "input weight")
	flag.StringVar(&o.gain, "k", "", "apply this gain k0,...,k5 instead of designing one")
	flag.StringVar(&o.trace, "trace", "", "write each answered state and the effort sent to this file")
	flag.BoolVar(&o.quiet, "quiet", false, "quiet: design and summary only")
	flag.Usage = usage
	// the other examples' spelling: --q W0,...,W5 the weights, -q (never a value) quiet;
	// Go's flag package reads -q and --q alike, so they are told apart here
	args := append([]string(nil), os.Args[1:]...)
	for i, a := range args {
		if a == "--" {
			break
		} else if a == "-q" {
			args[i] = "-quiet"
		} else if a == "--q" || strings.HasPrefix(a, "--q=") {
			args[i] = "-weights" + strings.TrimPrefix(a, "--q")
		}
	}
	if err := flag.CommandLine.Parse(args); err != nil {
		os.Exit(2)
	}
	if flag.NArg() > 0 {
		fail(2, "unexpected argument '%s' (-q takes no value; the weights are --q W0,...,W5)", flag.Arg(0))
	}
	if !(o.timeout > 0) || !(o.duration >= 0) || !(o.r > 0) || math.IsInf(o.r, 0) {
		fail(2, "--timeout and --r must be > 0 and --duration a number >= 0")
	}
	return o
}

// usage lists the options as they are typed: --q the weights, -q quiet, as in the other
// examples (Go's own listing would show the flags' internal names).
func usage() {
	out := flag.CommandLine.Output()
	fmt.Fprintf(out, "usage: %s [--prefix P] [--url URL] [--duration S] [--timeout S] [--q W0,...,W5]\n"+
		"       %*s [--r R] [--k K0,...,K5] [--trace FILE] [-q]\n\n"+
		"Balances the double inverted pendulum on a cart (DIPC) upright with LQR, in Go\n"+
		"through the client library's C ABI.\n\noptions:\n", name, len(name), "")
	typed := map[string]string{"prefix": "--prefix P", "url": "--url URL", "duration": "--duration S",
		"timeout": "--timeout S", "weights": "--q W0,...,W5", "r": "--r R", "k": "--k K0,...,K5",
		"trace": "--trace FILE", "quiet": "-q"}
	for _, f := range []string{"prefix", "url", "duration", "timeout", "trace", "quiet", "weights", "r", "k"} {
		fl := flag.Lookup(f)
		def := ""
		if fl.DefValue != "" && fl.DefValue != "false" && fl.DefValue != "0" {
			def = " (default " + fl.DefValue + ")"
		}
		fmt.Fprintf(out, "  %-16s %s%s\n", typed[f], fl.Usage, def)
	}
}

// locate: no --url: the URL a host's directory on LCM's default bus names for prefix
// (lag_client_locate, 1 s at most), said; else "" (LCM's default: a plant there, or one
// not started yet).
func locate(prefix string) string {
	var url [C.LAG_CLIENT_URL_LEN]C.char
	var cerr [256]C.char
	cprefix := C.CString(prefix)
	where := C.lag_client_locate(cprefix, C.LAG_CLIENT_LOCATE_WAIT_S, &url[0], C.size_t(len(url)),
		&cerr[0], C.size_t(len(cerr)))
	C.free(unsafe.Pointer(cprefix))
	if where < 0 {
		fail(2, "--prefix: %s", C.GoString(&cerr[0]))
	}
	if where != C.LAG_CLIENT_LOCATE_HOST {
		return ""
	}
	found := C.GoString(&url[0])
	fmt.Printf("%s: prefix %s runs on %s (the host's directory)\n", name, prefix, found)
	return found
}

// connect: the handle (C memory, freed by lag_client_destroy; the strings passed are
// copied by the library) and its scene, awaited.
func connect(o options, sig chan os.Signal) (*C.lag_client, *C.lag_client_scene) {
	var cerr [256]C.char
	if o.url == "" {
		o.url = locate(o.prefix)
	}
	curl, cprefix := C.CString(o.url), C.CString(o.prefix)
	c := C.lag_client_create(curl, cprefix, &cerr[0], C.size_t(len(cerr)))
	C.free(unsafe.Pointer(curl))
	C.free(unsafe.Pointer(cprefix))
	if c == nil {
		fail(1, "%s", C.GoString(&cerr[0]))
	}
	C.lag_client_on_event(c, C.lag_client_event_fn(C.goOnEvent), nil)
	sc := C.lag_client_scene_new() // the scene: opaque, read through accessors
	fmt.Printf("%s: waiting for the scene description on %s_SCENE\n", name, o.prefix)
	if !waitScene(c, sc, o.url, o.prefix, o.timeout, sig) {
		summary(c, "signal", 0, "") // SIGINT or SIGTERM while waiting: a run that ended
		os.Exit(0)
	}
	if model := C.GoString(C.lag_client_scene_model(sc)); model != "dipc" {
		fail(1, "prefix %s runs model '%s', not dipc", o.prefix, model)
	}
	return c, sc
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

// sceneParams: the scene's parameters by name (strings copied out of the scene).
func sceneParams(sc *C.lag_client_scene) map[string]float64 {
	p := map[string]float64{}
	for i := C.int(0); i < C.lag_client_scene_num_params(sc); i++ {
		p[C.GoString(C.lag_client_scene_param_name(sc, i))] = float64(C.lag_client_scene_param_value(sc, i))
	}
	return p
}

// gain: the design's, or --k's; refused unless it stabilizes the sampled loop.
func gain(o options, sc *C.lag_client_scene) (matrix, []float64) {
	h := float64(C.lag_client_scene_control_period(sc))
	Ad, Bd, K := design(sceneParams(sc), h, parseList(o.qweights, "--q"), o.r)
	fmt.Printf("%s: discrete LQR (h = %g s): K = [%s]\n", name, h, joinG(K))
	if o.gain != "" {
		K = parseList(o.gain, "--k")
		fmt.Printf("%s: applying the given gain K = [%s]\n", name, joinG(K))
	}
	Acl := closedLoop(Ad, Bd, K)
	if !stabilizes(Acl) {
		fail(1, "this gain does not stabilize the sampled loop")
	}
	return Acl, K
}

// run is what a run did: its states, peaks and end angles for the summary.
type run struct {
	states                int64
	tFirst, tLast, report float64
	peak, end             [3]float64
	maxU                  float64
	x0                    []float64
}

func (r *run) record(t float64, x []float64, u float64, quiet bool) {
	if r.states == 0 {
		r.tFirst, r.x0 = t, append([]float64(nil), x...)
	}
	r.states++
	r.tLast = t
	for k := 0; k < 3; k++ {
		r.peak[k] = math.Max(r.peak[k], math.Abs(x[k]))
	}
	r.maxU = math.Max(r.maxU, math.Abs(u))
	copy(r.end[:], x[:3])
	if !quiet && t-r.report >= 1.0 {
		r.report = t
		fmt.Printf("t=%8.3f  x=%+.5f  th1=%+.6f  th2=%+.6f  u=%+.4f\n", t, x[0], x[1], x[2], u)
	}
}

// stateVector: x from a state, false if it lacks a joint.
func stateVector(st *C.lag_client_state, x []float64) bool {
	for k, j := range [3]string{"theta0", "theta1", "theta2"} {
		cj := C.CString(j)
		i := C.lag_client_state_joint(st, cj)
		C.free(unsafe.Pointer(cj))
		if i < 0 {
			return false
		}
		x[k], x[3+k] = float64(st.position[i]), float64(st.velocity[i])
	}
	return true
}

func writeTrace(f *os.File, st *C.lag_client_state, u float64) {
	// sim time, positions, velocities, effort: %.17g reads back to the same double
	n := int(st.num_joints)
	fmt.Fprintf(f, "%.17g", float64(st.sim_time))
	for i := 0; i < n; i++ {
		fmt.Fprintf(f, " %.17g", float64(st.position[i]))
	}
	for i := 0; i < n; i++ {
		fmt.Fprintf(f, " %.17g", float64(st.velocity[i]))
	}
	fmt.Fprintf(f, " %.17g\n", u)
}

// balance answers every state until the run ends; returns how it ended.
func balance(c *C.lag_client, sc *C.lag_client_scene, K []float64, o options, trace *os.File,
	sig chan os.Signal, r *run) string {
	theta0 := C.CString("theta0") // the name commanded, in C memory for the whole run
	defer C.free(unsafe.Pointer(theta0))
	names := [1]*C.char{theta0}
	heard := float64(C.lag_client_now())
	x := make([]float64, N)
	var st C.lag_client_state
	for {
		select {
		case <-sig:
			return "signal"
		default:
		}
		if r.states > 0 && o.duration > 0 &&
			r.tLast-r.tFirst >= o.duration-0.5*float64(C.lag_client_scene_control_period(sc)) {
			return "duration"
		}
		// the next state not yet returned; a copy of one is answered by the library
		rc := C.lag_client_wait_state(c, 0.05, &st, C.size_t(unsafe.Sizeof(st)))
		switch {
		case rc < 0:
			fail(1, "%s", C.GoString(C.lag_client_errmsg(c)))
		case rc == C.LAG_CLIENT_OK:
			heard = float64(C.lag_client_now())
		case stopped.Load():
			return "stop"
		case float64(C.lag_client_now())-heard > o.timeout:
			return "silence"
		}
		if rc != C.LAG_CLIENT_OK || !stateVector(&st, x) {
			continue
		}
		u := 0.0
		for k := 0; k < N; k++ {
			u -= float64(K[k] * x[k]) // the rounded product, then the difference: C's order
		}
		if math.IsNaN(u) || math.IsInf(u, 0) {
			u = 0 // the library refuses a non-finite effort: send 0, as the C examples
		}
		cu := C.double(u)
		if C.lag_client_send_command(c, st.sim_time, 1, &names[0], &cu) != C.LAG_CLIENT_OK {
			fail(1, "%s", C.GoString(C.lag_client_errmsg(c)))
		}
		if trace != nil {
			writeTrace(trace, &st, u)
		}
		r.record(float64(st.sim_time), x, u, o.quiet)
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

func main() {
	o := parseOptions()
	checkLibrary()
	var trace *os.File
	if o.trace != "" {
		var err error
		if trace, err = os.Create(o.trace); err != nil {
			fail(1, "--trace: %v", err)
		}
		defer trace.Close()
	}
	sig := make(chan os.Signal, 1)
	signal.Notify(sig, syscall.SIGINT, syscall.SIGTERM)
	c, sc := connect(o, sig)
	defer C.lag_client_destroy(c)
	defer C.lag_client_scene_free(sc)
	Acl, K := gain(o, sc)
	r := &run{tFirst: math.NaN(), tLast: math.NaN(), report: math.Inf(-1),
		end: [3]float64{math.NaN(), math.NaN(), math.NaN()}}
	end := balance(c, sc, K, o, trace, sig, r)
	pred := predict(Acl, r.x0, r.states)
	summary(c, end, r.states, fmt.Sprintf("t_first=%.6f t_last=%.6f max_abs_theta0=%.6g "+
		"max_abs_theta1=%.6g max_abs_theta2=%.6g max_abs_effort=%.6g end_theta1=%.3g end_theta2=%.3g "+
		"pred_max_abs_theta0=%.6g pred_max_abs_theta1=%.6g pred_max_abs_theta2=%.6g",
		r.tFirst, r.tLast, r.peak[0], r.peak[1], r.peak[2], r.maxU, r.end[1], r.end[2],
		pred[0], pred[1], pred[2]))
}
