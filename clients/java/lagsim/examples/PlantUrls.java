package lagsim.examples;

import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * The two LCM URLs of a lagsim plant whose lcm.url is {@code url} (null or "": the
 * environment's LCM_DEFAULT_URL, else LCM's default): the daemon publishes
 * PREFIX_STATE, _STATUS, _EVENT and _SCENE on the state URL (the URL itself) and listens
 * for PREFIX_COMMAND and _CONTROL on the command URL, the same group and options on the
 * next port; memq:// is both.
 *
 * <pre>
 *     LCM states = new LCM(PlantUrls.state(null)), commands = new LCM(PlantUrls.command(null));
 * </pre>
 *
 * The C library's rule (lagsim_bus.h), checked against the same cases
 * (tests/net/plant_urls.txt). A URL a plant cannot have throws IllegalArgumentException.
 */
public final class PlantUrls {
    private static final String DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=0"; // LCM's own
    private static final String N3 = "(0|[1-9]\\d{0,2})", N5 = "(0|[1-9]\\d{0,4})"; // no leading
    // zeros: LCM reads the group with inet_aton and the port with strtol(.., 0), as octal
    private static final Pattern UDPM = Pattern.compile(
        "^udpm://(?:(" + N3 + "\\." + N3 + "\\." + N3 + "\\." + N3 + ")(:" + N5 + ")?)?(\\?.*)?$");

    private PlantUrls() {}

    /** The state URL: where the plant's states, status, events and scene are. */
    public static String state(String url) { return both(url)[0]; }

    /** The command URL: where commands and control requests go. */
    public static String command(String url) { return both(url)[1]; }

    /** {state URL, command URL}. */
    public static String[] both(String url) {
        if (url == null || url.isEmpty()) {
            url = System.getenv("LCM_DEFAULT_URL");
            if (url == null || url.isEmpty()) url = DEFAULT_URL;
        }
        if (url.length() >= 256) throw new IllegalArgumentException("LCM URL longer than 255 characters");
        if (url.equals("memq://")) return new String[] {url, url};
        Matcher m = UDPM.matcher(url);
        if (!m.matches())
            throw new IllegalArgumentException("a lagsim plant speaks udpm://GROUP:PORT (or memq:// in one "
                                               + "process), not '" + url + "'");
        String group = "239.255.76.67";
        int port = 7667;
        if (m.group(1) != null) {
            int[] o = new int[4];
            for (int k = 0; k < 4; k++) o[k] = Integer.parseInt(m.group(k + 2));
            if (o[0] < 224 || o[0] > 239 || o[1] > 255 || o[2] > 255 || o[3] > 255)
                throw new IllegalArgumentException("the group of '" + url + "' is not a multicast address");
            group = o[0] + "." + o[1] + "." + o[2] + "." + o[3];
            if (m.group(6) != null) port = Integer.parseInt(m.group(7));
            if (port < 1 || port > 65534)
                throw new IllegalArgumentException("expected a port from 1 to 65534 in '" + url
                                                   + "' (commands go to the next port)");
        }
        String query = m.group(8) == null ? "" : m.group(8);
        return new String[] {"udpm://" + group + ":" + port + query,
                             "udpm://" + group + ":" + (port + 1) + query};
    }

    /** Checks the rule against a table of cases: java -cp ... lagsim.examples.PlantUrls TABLE */
    public static void main(String[] args) throws java.io.IOException {
        int cases = 0, fails = 0;
        for (String line : java.nio.file.Files.readAllLines(java.nio.file.Paths.get(args[0]))) {
            line = line.trim();
            if (line.isEmpty() || line.startsWith("#")) continue;
            String[] f = line.split(" \\| ");
            String base = f[0].trim();
            String[] got;
            try {
                got = both(base.equals("(none)") ? null : base);
            } catch (IllegalArgumentException e) {
                got = new String[] {"ERROR", "ERROR"};
            }
            cases++;
            if (!got[0].equals(f[1].trim()) || !got[1].equals(f[2].trim())) {
                System.out.println("FAIL: '" + base + "' gives " + got[0] + " " + got[1] + ", expected "
                                   + f[1].trim() + " " + f[2].trim());
                fails++;
            }
        }
        System.out.println("PlantUrls: " + cases + " cases, " + fails + " failures");
        System.exit(fails == 0 && cases >= 10 ? 0 : 1);
    }
}
