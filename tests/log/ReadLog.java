// Reads an LCM log with lcm.jar's own reader (lcm.logging.Log: what lcm-spy's log playback
// and lcm-logplayer-gui read with) and prints "records <n> crc <crc32 of every channel and
// payload, in order> numbered <true|false> ordered <true|false>".
//   java -cp /usr/share/java/lcm.jar ReadLog.java LOG
import java.io.EOFException;
import java.nio.charset.StandardCharsets;
import java.util.zip.CRC32;
import lcm.logging.Log;

public class ReadLog {
    public static void main(String[] args) throws Exception {
        Log log = new Log(args[0], "r");
        CRC32 crc = new CRC32();
        long n = 0, lastUtime = Long.MIN_VALUE;
        boolean numbered = true, ordered = true;
        try {
            for (;;) {
                Log.Event e = log.readNext();
                numbered &= e.eventNumber == n;
                ordered &= e.utime >= lastUtime;
                lastUtime = e.utime;
                crc.update(e.channel.getBytes(StandardCharsets.UTF_8));
                crc.update(e.data);
                n++;
            }
        } catch (EOFException end) {
            // the end of the log
        }
        log.close();
        System.out.println("records " + n + " crc " + crc.getValue() + " numbered " + numbered
                           + " ordered " + ordered);
    }
}
