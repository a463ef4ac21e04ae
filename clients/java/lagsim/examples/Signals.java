package lagsim.examples;

/**
 * SIGINT and SIGTERM as a flag a controller's loop looks at, instead of the end of the
 * process: {@link #install()} once, then {@link #signalled()} in every wait (the Java
 * Controller, and the MATLAB/Octave lagsim_controller through javaMethod, whose JVM runs
 * inside Octave). The handler, on a thread of the JVM's, only sets the flag.
 *
 * Through reflection: sun.misc.Signal (module jdk.unsupported) has no public replacement,
 * and naming it would make javac warn. Where it is missing, install() returns false and
 * the signals keep their default (the process ends).
 */
public final class Signals {
    private static volatile boolean signalled;

    private Signals() {}

    /** True once SIGINT or SIGTERM came after {@link #install()}. */
    public static boolean signalled() { return signalled; }

    /** Handles SIGINT and SIGTERM by setting the flag; false (and a line on stderr) when
     *  this JVM cannot. */
    public static boolean install() {
        try {
            Class<?> sig = Class.forName("sun.misc.Signal");
            Class<?> handler = Class.forName("sun.misc.SignalHandler");
            Object h = java.lang.reflect.Proxy.newProxyInstance(handler.getClassLoader(),
                new Class<?>[] {handler}, (proxy, m, a) -> {
                    switch (m.getName()) {
                    case "handle": signalled = true; return null;
                    case "hashCode": return System.identityHashCode(proxy);
                    case "equals": return proxy == a[0];
                    default: return "lagsim signal handler";
                    }
                });
            for (String n : new String[] {"INT", "TERM"})
                sig.getMethod("handle", sig, handler).invoke(null, sig.getConstructor(String.class).newInstance(n), h);
            return true;
        } catch (ReflectiveOperationException | RuntimeException e) {
            Throwable c = e.getCause() != null ? e.getCause() : e;
            System.err.println("lagsim: SIGINT and SIGTERM end the process (" + c + ")");
            return false;
        }
    }
}
