package lagsim.examples;

import java.io.FileWriter;
import java.io.IOException;
import java.io.PrintWriter;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

import lagsim.control_t;
import lagsim.event_t;
import lagsim.joint_command_t;
import lagsim.joint_state_t;
import lagsim.reference_t;
import lagsim.scene_t;
import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;

/**
 * What a Java example controller needs: options, connect, wait for the scene, answer
 * states until the run ends, a summary line.
 *
 * <pre>
 *   Controller ctl = new Controller("DipcBalance", "DIPC", "dipc");
 *   ctl.option("r", "1", "input weight");             // the example's own options
 *   ctl.start(args);                                  // parses, connects, waits for the scene
 *   joint_state_t st;
 *   while ((st = ctl.nextState()) != null)            // each newest state once
 *       ctl.command(st.sim_time, new String[] {"theta0"}, new double[] {u});
 *   ctl.finish("states=" + n);                        // "DipcBalance: summary end=... states=..."
 * </pre>
 *
 * A scene with a {@code reference:} has lagsimd publish a reference_t on
 * &lt;PREFIX&gt;_REFERENCE just before each state, with that state's sim_time;
 * {@link #reference()} hands the law the one that belongs to the state nextState returned
 * (docs/clients.md, "Reading the reference").
 *
 * LCM's Java library delivers messages on its own receive thread; the handlers here only
 * keep the newest state and reference and note the daemon's stop, and the caller's thread
 * does the work. A run ends when the daemon publishes its stop event, when nothing came from the
 * daemon (state, status or event) for --timeout wall seconds, or after --duration s of
 * sim time from the first state, or on SIGINT or SIGTERM; endReason says which (stop,
 * silence, duration, signal; a signal while it waits for the scene prints the summary with
 * states=0). Exit status: 0 for these; 1 when no scene came within --timeout or it is another model's;
 * 2 bad usage.
 */
public final class Controller {
    public final String name, model;
    private final Map<String, String[]> opts = new LinkedHashMap<>(); // key -> {value, help}
    public final Map<String, Double> params = new HashMap<>();
    public boolean quiet;
    public scene_t scene;
    public String endReason;
    public long dropped;

    private LCM lcm;      // the plant's state URL: states, status, events, scene
    private LCM lcmCmd;   // its command URL: commands and control (PlantUrls)
    private String prefix;
    private double duration, timeout;
    private PrintWriter trace;
    private final Object lock = new Object();
    private joint_state_t latest, current;
    // the newest reference received; the one that was newest when `latest` came (its
    // own, published just before it, unless UDP lost that); the one of `current`
    private reference_t refNewest, refLatest, refCurrent;
    /** States handed out whose own reference did not come (the last one was kept). */
    public long referencesStale;
    // the last command sent and the state it answered (a copy of it is answered again)
    private joint_command_t lastCmd;
    private long lastGeneration, lastStep;
    private double lastTime;
    /** States held until the scene of their generation came. */
    public long held;
    /** The pace of DESCRIBE while a scene is awaited (the C client's too). */
    static final long DESCRIBE_NS = 250_000_000L;
    /** Copies of a state answered again with the same command. */
    public long repeats;
    private boolean stopped;
    private long heardNanos;
    private double tFirst = Double.NaN;

    public Controller(String name, String defaultPrefix, String model) {
        this.name = name;
        this.model = model;
        option("prefix", defaultPrefix, "channel prefix");
        option("url", "", "the plant's LCM URL, its lcm.url (default: the URL a host's directory "
                          + "on LCM's default bus names for --prefix, else LCM's default, honours "
                          + "LCM_DEFAULT_URL); commands go to the next port");
        option("duration", "0", "stop after S s of sim time from the first state (0: until the daemon stops)");
        option("timeout", "5", "wall s without a scene, or without any message once running, before ending");
        option("trace", "", "write each answered state and the efforts sent to this file");
    }

    public void option(String key, String def, String help) {
        opts.put(key, new String[] {def, help});
    }

    public String get(String key) { return opts.get(key)[0]; }

    /** A finite number, or exit 2 with a message. */
    public double number(String key) {
        try {
            double v = Double.parseDouble(get(key));
            if (Double.isFinite(v)) return v;
        } catch (NumberFormatException e) { /* below */ }
        return usageError("--" + key + " wants a number, not " + get(key));
    }

    /** n comma-separated finite numbers, or exit 2. */
    public double[] list(String key, int n) {
        String[] f = get(key).split(",", -1);
        double[] v = new double[f.length];
        try {
            for (int i = 0; i < f.length; i++) {
                v[i] = Double.parseDouble(f[i]);
                if (!Double.isFinite(v[i])) throw new NumberFormatException();
            }
        } catch (NumberFormatException e) {
            f = new String[0];
        }
        if (f.length != n) usageError("--" + key + " wants " + n + " comma-separated numbers");
        return v;
    }

    public double usageError(String msg) {
        System.err.println(name + ": " + msg);
        System.exit(2);
        return 0;
    }

    private void usage() {
        System.out.println("usage: " + name + " [options]");
        for (Map.Entry<String, String[]> e : opts.entrySet())
            System.out.printf("  --%-10s %s (default %s)%n", e.getKey(), e.getValue()[1],
                              e.getValue()[0].isEmpty() ? "none" : e.getValue()[0]);
        System.out.println("  -q           quiet: summary only");
    }

    private void fail(String msg) {
        System.err.println(name + ": " + msg);
        System.exit(1);
    }

    /** Parses args, connects, subscribes, waits for the scene description. */
    public void start(String[] args) throws IOException, InterruptedException {
        for (int i = 0; i < args.length; i++) {
            String a = args[i];
            if (a.equals("--help") || a.equals("-h")) {
                usage();
                System.exit(0);
            } else if (a.equals("-q")) {
                quiet = true;
            } else if (a.startsWith("--") && opts.containsKey(a.substring(2)) && i + 1 < args.length) {
                opts.get(a.substring(2))[0] = args[++i];
            } else {
                usage();
                usageError("unknown or incomplete option '" + a + "'");
            }
        }
        prefix = get("prefix");
        duration = number("duration");
        timeout = number("timeout");
        if (!(timeout > 0) || !(duration >= 0)) usageError("--timeout must be > 0 and --duration >= 0");
        if (!get("trace").isEmpty()) trace = new PrintWriter(new FileWriter(get("trace")));

        String[] urls;
        try {
            urls = PlantUrls.both(get("url"));
        } catch (IllegalArgumentException e) {
            usageError("--url: " + e.getMessage());
            return;
        }
        if (get("url").isEmpty()) urls = located(urls);
        lcm = new LCM(urls[0]);
        lcmCmd = urls[1].equals(urls[0]) ? lcm : new LCM(urls[1]);
        heardNanos = System.nanoTime();
        // one subscriber for the daemon's channels; runs on LCM's receive thread
        LCMSubscriber sub = new LCMSubscriber() {
            @Override
            public void messageReceived(LCM l, String channel, LCMDataInputStream ins) {
                synchronized (lock) {
                    heardNanos = System.nanoTime();
                    try { // only messages that decode whole, string lengths checked first
                        if (channel.endsWith("_STATE")) {
                            latest = BoundedInput.decode(ins, joint_state_t::new);
                            refLatest = refNewest;
                        } else if (channel.endsWith("_REFERENCE")) {
                            refNewest = BoundedInput.decode(ins, reference_t::new);
                        } else if (channel.endsWith("_SCENE")) {
                            scene = BoundedInput.decode(ins, scene_t::new);
                            params.clear();
                            for (int k = 0; k < scene.num_params; k++)
                                params.put(scene.param_name[k], scene.param_value[k]);
                        } else if (channel.endsWith("_EVENT")) {
                            if (BoundedInput.decode(ins, event_t::new).kind.equals("stop")) stopped = true;
                        }
                    } catch (IOException | RuntimeException e) { // not one of ours, or damaged
                        dropped++;
                    }
                    lock.notifyAll();
                }
            }
        };
        String ch = prefix + "_";
        lcm.subscribe(java.util.regex.Pattern.quote(ch) + "(STATE|SCENE|EVENT|STATUS|REFERENCE)", sub);
        // subscribed: from here on no state is missed (test harnesses wait for this line)
        System.out.println(name + ": waiting for the scene description on " + ch + "SCENE");
        System.out.flush();
        long deadline = System.nanoTime() + (long) (timeout * 1e9);
        long nextAsk = System.nanoTime();
        Signals.install(); // SIGINT, SIGTERM: endReason "signal", not the JVM's end
        synchronized (lock) {
            while (scene == null) {
                if (Signals.signalled()) { // a run that ended before its scene came: no failure
                    endReason = "signal";
                    break;
                }
                long now = System.nanoTime();
                if (now >= deadline)
                    fail(String.format("no scene on %sSCENE within %g s (is lagsimd running with this prefix?)",
                                       ch, timeout));
                if (now >= nextAsk) { // DESCRIBE every 0.25 s until the scene comes
                    askScene();
                    nextAsk = now + DESCRIBE_NS;
                }
                lock.wait(50);
            }
        }
        if (scene == null) System.exit(finish("states=0"));
        if (!scene.model.equals(model)) fail("prefix " + prefix + " runs model " + scene.model + ", not " + model);
    }

    /** No --url: the URLs a host's directory on LCM's default bus names for the prefix
     *  (Locate, 1 s at most), else urls (LCM's default: a plant there, or one not started
     *  yet). */
    private String[] located(String[] urls) throws IOException, InterruptedException {
        Locate l;
        try {
            l = Locate.plant(prefix, Locate.WAIT_S);
        } catch (IllegalArgumentException e) {
            usageError("--prefix: " + e.getMessage());
            return urls;
        }
        if (!l.host()) return urls;
        System.out.println(name + ": prefix " + prefix + " runs on " + l.url() + " (the host's directory)");
        return PlantUrls.both(l.url());
    }

    private void askScene() {
        control_t req = new control_t();
        req.utime = System.currentTimeMillis() * 1000;
        req.request = control_t.DESCRIBE;
        req.q = new double[0];
        req.qd = new double[0];
        req.key = "";
        req.value = "";
        lcmCmd.publish(prefix + "_CONTROL", req);
    }

    /** st, or the newest state since, once the scene of its generation came (the daemon
     *  publishes it just before the first state of a generation; DESCRIBE asks for it again
     *  every 0.25 s, for when UDP lost it); null when the run ended first. So the law never
     *  answers a state with another run's or scene's parameters (docs/clients.md). Called
     *  holding the lock. */
    private joint_state_t withScene(joint_state_t st) throws InterruptedException {
        long nextAsk = System.nanoTime();
        while (st.generation != scene.generation) {
            if (Signals.signalled()) { endReason = "signal"; return null; }
            if (stopped) { endReason = "stop"; return null; }
            long now = System.nanoTime();
            if (now - heardNanos > (long) (timeout * 1e9)) { endReason = "silence"; return null; }
            if (now >= nextAsk) {
                askScene();
                nextAsk = now + DESCRIBE_NS;
            }
            lock.wait(20);
            if (latest != null) { st = latest; latest = null; } // a newer state: that one
        }
        return st;
    }

    /** The newest state not yet returned, or null when the run has ended (see endReason).
     *  A copy of the state answered last (same generation, step and sim time: the daemon
     *  published it again because no answer reached it) is answered at once with the same
     *  command and not returned: every state received is answered, the law runs once per
     *  state (a law run for every copy would cost a think time per copy and fall behind for
     *  good: docs/clients.md, the rule). A state is returned only once scene (and params)
     *  is the scene of its generation. */
    public joint_state_t nextState() throws InterruptedException {
        synchronized (lock) {
            if (endReason != null) return null;
            joint_state_t st;
            for (;;) {
                while (latest == null) {
                    if (Signals.signalled()) { endReason = "signal"; return null; }
                    if (stopped) { endReason = "stop"; return null; }
                    if (System.nanoTime() - heardNanos > (long) (timeout * 1e9)) {
                        endReason = "silence";
                        return null;
                    }
                    lock.wait(50);
                }
                st = latest;
                latest = null;
                if (lastCmd == null || st.generation != lastGeneration || st.step != lastStep ||
                    st.sim_time != lastTime) {
                    if (st.generation == scene.generation) break;
                    held++;
                    if ((st = withScene(st)) == null) return null;
                    break;
                }
                lcmCmd.publish(prefix + "_COMMAND", lastCmd);
                repeats++;
            }
            current = st;
            refCurrent = refLatest;
            if (refCurrent != null && refCurrent.sim_time != st.sim_time) referencesStale++;
            if (Double.isNaN(tFirst)) tFirst = st.sim_time;
            if (duration > 0 && st.sim_time - tFirst >= duration - 0.5 * scene.control_period)
                endReason = "duration"; // this state is still answered; the next call ends
            return st;
        }
    }

    /** Publishes efforts for the named joints, answering the state at simTime. */
    public void command(double simTime, String[] names, double[] efforts) {
        joint_command_t cmd = new joint_command_t();
        cmd.utime = System.currentTimeMillis() * 1000;
        cmd.sim_time = simTime;
        joint_state_t st = current;
        cmd.generation = st != null ? st.generation : 0; // of the state it answers (0: none yet)
        cmd.num_joints = (short) names.length;
        cmd.name = names.clone();
        cmd.effort = new double[efforts.length];
        for (int k = 0; k < efforts.length; k++) // never send NaN
            cmd.effort[k] = Double.isFinite(efforts[k]) ? efforts[k] : 0.0;
        lcmCmd.publish(prefix + "_COMMAND", cmd);
        if (st != null && st.sim_time == simTime) {
            synchronized (lock) {
                lastCmd = cmd;
                lastGeneration = st.generation;
                lastStep = st.step;
                lastTime = simTime;
            }
        }
        if (trace != null && st != null && st.sim_time == simTime) {
            // sim_time, positions, velocities, efforts sent: Double.toString reads back exactly
            List<String> f = new ArrayList<>();
            f.add(Double.toString(st.sim_time));
            for (double v : st.position) f.add(Double.toString(v));
            for (double v : st.velocity) f.add(Double.toString(v));
            for (double v : cmd.effort) f.add(Double.toString(v));
            trace.println(String.join(" ", f));
        }
    }

    /** Index of joint `joint` in a state, or -1. */
    public static int joint(joint_state_t st, String joint) {
        for (int k = 0; k < st.num_joints; k++)
            if (st.name[k].equals(joint)) return k;
        return -1;
    }

    /** The scene's reference for the state nextState returned last: the reference_t
     *  published with it (the same sim_time; r and rdot of the joints the scene gives a
     *  reference), or, when UDP lost that one, the last one received before it (its
     *  sim_time is older; counted in referencesStale). null before the first: a scene
     *  without a reference publishes none. */
    public reference_t reference() {
        synchronized (lock) {
            return refCurrent;
        }
    }

    /** Index of joint `joint` in a reference, or -1 (no reference for it, or ref null). */
    public static int joint(reference_t ref, String joint) {
        if (ref == null) return -1;
        for (int k = 0; k < ref.num_joints; k++)
            if (ref.name[k].equals(joint)) return k;
        return -1;
    }

    /** Prints the summary line, ending "dropped=N repeats=N", then, when a reference came
     *  (a scene with a reference), "references_stale=N"; returns the exit status (0). The
     *  LCM stays open until the process exits (closing it makes its receive thread print a
     *  socket exception). */
    public int finish(String summary) {
        boolean ref;
        synchronized (lock) {
            ref = refNewest != null;
        }
        System.out.println(name + ": summary end=" + endReason + " " + summary + " dropped=" + dropped
                           + " repeats=" + repeats + (ref ? " references_stale=" + referencesStale : ""));
        System.out.flush();
        if (trace != null) trace.close();
        return 0;
    }
}
