package lagsim.examples;

import java.io.DataInput;
import java.io.IOException;
import java.lang.reflect.Constructor;
import java.lang.reflect.Field;
import java.lang.reflect.InvocationTargetException;
import java.util.Arrays;

import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMDataOutputStream;
import lcm.lcm.LCMEncodable;

/**
 * The bytes of one received message, for lcm-gen's Java decoders, with every string
 * length checked before the decoder allocates for it.
 *
 * lcm-gen's Java code reads a string as {@code new char[ins.readInt() - 1]} and only then
 * reads its bytes: a forged length of 0x7fffffff throws OutOfMemoryError (not an
 * IOException: it escapes the handler and ends LCM's receive thread, so the controller
 * hears nothing more), and a length of 10^9 allocates 2 GB for a 77-byte message. lagsim's
 * messages have no int32 field, so every int32 their decoders read is a string length
 * (counting its NUL): one below 1 or above the bytes left is refused here with an
 * IOException, which the handler counts as a dropped message like any other damage.
 *
 * {@link #decode} also keeps only a message that decodes whole, as the C client does:
 *
 * <pre>
 *     joint_state_t st = BoundedInput.decode(ins, joint_state_t::new);  // ins: the handler's
 * </pre>
 */
public final class BoundedInput implements DataInput {
    private final LCMDataInputStream in;

    /** An lcm-gen decoder: the generated type's constructor from a DataInput. */
    public interface Decoder<T extends LCMEncodable> {
        T decode(DataInput in) throws IOException;
    }

    /**
     * The message in the unread bytes of {@code ins}, decoded by {@code decoder} with its
     * string lengths checked; IOException unless it decodes whole: lcm-gen's decoder reads
     * a string without its NUL, or with bytes left over, as if nothing were wrong, so the
     * message must encode back to the very bytes that came; every double in it must be
     * finite, and no string may hold a NUL but the one it ends with (lcm-gen's decoder
     * keeps an inner one, which encodes back to the same bytes). Whatever the bytes, the only exception is IOException: one that escaped a
     * handler would end LCM's receive thread.
     */
    public static <T extends LCMEncodable> T decode(LCMDataInputStream ins, Decoder<T> decoder)
            throws IOException {
        byte[] buf = ins.getBuffer();
        int off = ins.getBufferOffset(), len = ins.available();
        T msg;
        try {
            msg = decoder.decode(new BoundedInput(buf, off, len));
        } catch (RuntimeException e) { // a negative count: NegativeArraySizeException, ...
            throw new IOException("does not decode: " + e, e);
        }
        LCMDataOutputStream out = new LCMDataOutputStream(len);
        msg.encode(out);
        if (out.size() != len || !sameBytes(out.getBuffer(), buf, off, len))
            throw new IOException("does not encode back to the bytes received");
        try {
            for (Field f : msg.getClass().getFields()) {
                Object v = f.get(msg);
                if (v instanceof Double && !Double.isFinite((Double) v))
                    throw new IOException("non-finite " + f.getName());
                if (v instanceof double[])
                    for (double x : (double[]) v)
                        if (!Double.isFinite(x)) throw new IOException("non-finite " + f.getName());
                if (v instanceof String && ((String) v).indexOf('\0') >= 0)
                    throw new IOException("a NUL inside " + f.getName());
                if (v instanceof String[])
                    for (String x : (String[]) v)
                        if (x.indexOf('\0') >= 0) throw new IOException("a NUL inside " + f.getName());
            }
        } catch (IllegalAccessException e) {
            throw new IOException(e);
        }
        return msg;
    }

    /**
     * The message of the lcm-gen type named {@code type} ("lagsim.joint_state_t") in the
     * bytes {@code data}, or null when they do not decode whole, checked as
     * {@link #decode(LCMDataInputStream, Decoder)} checks them: for callers that cannot
     * pass a decoder or catch an IOException by its class, such as MATLAB and GNU Octave,
     * which hand over a received message's bytes
     * ({@code lcm.lcm.MessageAggregator.Message.data}) and get [] for null.
     * IllegalArgumentException for a name that is no lcm-gen type.
     */
    public static LCMEncodable tryDecode(byte[] data, String type) {
        Constructor<? extends LCMEncodable> make;
        try {
            make = Class.forName(type).asSubclass(LCMEncodable.class).getConstructor(DataInput.class);
        } catch (ClassNotFoundException | ClassCastException | NoSuchMethodException e) {
            throw new IllegalArgumentException("no lcm-gen type " + type, e);
        }
        try {
            return decode(new LCMDataInputStream(data), in -> {
                try {
                    return make.newInstance(in);
                } catch (InvocationTargetException e) { // the decoder's own exception
                    if (e.getCause() instanceof IOException) throw (IOException) e.getCause();
                    throw new IOException("does not decode: " + e.getCause(), e.getCause());
                } catch (ReflectiveOperationException e) {
                    throw new IOException(e);
                }
            });
        } catch (IOException e) {
            return null;
        }
    }

    /** The unread bytes of {@code ins} (the stream LCM hands a subscriber). */
    public BoundedInput(LCMDataInputStream ins) {
        this(ins.getBuffer(), ins.getBufferOffset(), ins.available());
    }

    public BoundedInput(byte[] buf, int offset, int length) {
        in = new LCMDataInputStream(buf, offset, length);
    }

    /** A string's length (with its NUL): 1 to the bytes left, else IOException. */
    @Override
    public int readInt() throws IOException {
        int n = in.readInt();
        if (n < 1 || n > in.available())
            throw new IOException("string length " + n + " with " + in.available() + " bytes left");
        return n;
    }

    @Override public void readFully(byte[] b) throws IOException { in.readFully(b); }
    @Override public void readFully(byte[] b, int off, int len) throws IOException { in.readFully(b, off, len); }
    @Override public int skipBytes(int n) { return in.skipBytes(n); }
    @Override public boolean readBoolean() throws IOException { return in.readBoolean(); }
    @Override public byte readByte() throws IOException { return in.readByte(); }
    @Override public int readUnsignedByte() throws IOException { return in.readUnsignedByte(); }
    @Override public short readShort() throws IOException { return in.readShort(); }
    @Override public int readUnsignedShort() throws IOException { return in.readUnsignedShort(); }
    @Override public char readChar() throws IOException { return in.readChar(); }
    @Override public long readLong() throws IOException { return in.readLong(); }
    @Override public float readFloat() throws IOException { return in.readFloat(); }
    @Override public double readDouble() throws IOException { return in.readDouble(); }
    @Override public String readLine() throws IOException { return in.readLine(); }
    @Override public String readUTF() throws IOException { return in.readUTF(); }

    /** a[0..len) equals b[off..off+len) (Java 8 has no ranged Arrays.equals). */
    private static boolean sameBytes(byte[] a, byte[] b, int off, int len) {
        for (int i = 0; i < len; i++)
            if (a[i] != b[off + i]) return false;
        return true;
    }
}
