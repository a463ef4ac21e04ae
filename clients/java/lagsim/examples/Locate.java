package lagsim.examples;

import java.io.IOException;
import java.util.regex.Pattern;

import lagsim.event_t;
import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;

/**
 * Where the plant on a prefix runs when a program was given its prefix and no URL: a host
 * of plants ({@code lagsimd --plants}) runs each plant on a URL of its own and keeps a
 * directory on LCM's default bus (LCM_DEFAULT_URL, else LCM's default), where every 0.5 s
 * each plant's {@code plant} event names its state URL.
 *
 * <pre>
 *     Locate l = Locate.plant("ALICE", Locate.WAIT_S);
 *     String url = l.host() ? l.url() : "";                // "": LCM's default
 * </pre>
 *
 * The rule is the C library's ({@code lag_client_locate}, docs/protocol.md, "A host's
 * directory"), and the trace {@code directory} of tests/protocol/traces holds both to it:
 * it listens to PREFIX_EVENT, _STATE, _STATUS and _SCENE on the default bus until the first
 * message that decides, at most waitS, and asks nothing of any plant. The prefix's state,
 * status or scene, or an event of another kind than {@code plant}, is the plant itself
 * (HERE); a {@code plant} event whose detail is a URL a plant can have ({@link PlantUrls}),
 * other than the default bus's, names where it runs (HOST); anything else decides nothing,
 * and nothing within waitS is NONE. The MATLAB/Octave controllers call it too.
 */
public final class Locate {
    /** Nothing of the prefix within the wait: no plant yet, or no directory. */
    public static final int NONE = 0;
    /** A plant of the default bus itself. */
    public static final int HERE = 1;
    /** A host's directory names another URL: {@link #url()}. */
    public static final int HOST = 2;
    /** A directory's two announcements. */
    public static final double WAIT_S = 1.0;

    private final int where;
    private final String url;

    private Locate(int where, String url) {
        this.where = where;
        this.url = url;
    }

    /** NONE, HERE or HOST. */
    public int where() { return where; }

    /** Whether a host's directory named another URL for the prefix. */
    public boolean host() { return where == HOST; }

    /** The URL to talk to the plant on: the one the directory named (HOST), else the default bus's state URL. */
    public String url() { return url; }

    private static LCM directory;
    private static String directoryUrl;

    /** One LCM on the default bus for the process, kept open: closing one makes its receive
     *  thread print a socket exception. */
    private static synchronized LCM directory(String url) throws IOException {
        if (directory == null || !url.equals(directoryUrl)) {
            directory = new LCM(url);
            directoryUrl = url;
        }
        return directory;
    }

    private static final Pattern PREFIX = Pattern.compile("[A-Za-z0-9_]{1,53}");

    /** Where the plant on prefix runs; IllegalArgumentException for a prefix a plant cannot
     *  have or a bad LCM_DEFAULT_URL, IOException when LCM cannot listen there. */
    public static Locate plant(String prefix, double waitS) throws IOException, InterruptedException {
        if (prefix == null || !PREFIX.matcher(prefix).matches())
            throw new IllegalArgumentException("a prefix of 1 to 53 letters, digits or _, not '" + prefix + "'");
        final String here = PlantUrls.state(null);
        final Object lock = new Object();
        final String[] found = {null};
        final int[] decided = {-1};
        final String event = prefix + "_EVENT";
        LCMSubscriber sub = new LCMSubscriber() {
            @Override
            public void messageReceived(LCM l, String channel, LCMDataInputStream ins) {
                synchronized (lock) {
                    if (decided[0] >= 0) return;
                    if (!channel.equals(event)) {
                        decided[0] = HERE; // its state, status or scene
                    } else {
                        try {
                            event_t ev = BoundedInput.decode(ins, event_t::new);
                            if (!ev.kind.equals("plant")) {
                                decided[0] = HERE;
                            } else {
                                String u = PlantUrls.state(ev.detail);
                                if (!u.equals(here)) {
                                    found[0] = u;
                                    decided[0] = HOST;
                                }
                            }
                        } catch (IOException | IllegalArgumentException e) {
                            return; // undecodable, or no URL a plant can have: decides nothing
                        }
                    }
                    lock.notifyAll();
                }
            }
        };
        LCM lcm = directory(here);
        String re = Pattern.quote(prefix + "_") + "(EVENT|STATE|STATUS|SCENE)";
        lcm.subscribe(re, sub);
        long end = System.nanoTime() + (long) (waitS * 1e9);
        int where;
        synchronized (lock) {
            for (long left; decided[0] < 0 && (left = end - System.nanoTime()) > 0;)
                lock.wait(Math.max(1, left / 1_000_000));
            where = decided[0] < 0 ? NONE : decided[0];
        }
        lcm.unsubscribe(re, sub);
        return new Locate(where, where == HOST ? found[0] : here);
    }
}
