"""LCM's log format for the Python tests, read and written in one place: a record is the
sync word 0xEDA1DA01, its event number (8 bytes), timestamp (8), channel length (4), data
length (4), the channel, the data; all big-endian (lcm/eventlog.h)."""
import struct

SYNC = 0xEDA1DA01


def records(path, whole=False):
    """[(eventnum, timestamp, channel, data, offset)] of a log (offset: where the record's
    data starts in the file). whole: a damaged or cut record raises ValueError (a log the
    test's own processes wrote and closed); else the records before it are returned (a log
    still being written, or one damaged on purpose)."""
    out = []
    with open(path, "rb") as f:
        b = f.read()
    i = 0
    while i + 28 <= len(b):
        sync, num, ts, clen, dlen = struct.unpack_from(">IqqII", b, i)
        if sync != SYNC or i + 28 + clen + dlen > len(b):
            break
        out.append((num, ts, b[i + 28:i + 28 + clen].decode(), b[i + 28 + clen:i + 28 + clen + dlen],
                    i + 28 + clen))
        i += 28 + clen + dlen
    if whole and i != len(b):
        raise ValueError(f"{path}: not a whole record at byte {i}")
    return out


def read_log(path):
    """[(timestamp, channel, data)] of a log, up to its first damaged record."""
    return [(ts, ch, data) for _, ts, ch, data, _ in records(path)]


def write_log(path, records):
    """Writes [(timestamp, channel, data)], numbered from 0."""
    with open(path, "wb") as f:
        for k, (ts, ch, data) in enumerate(records):
            c = ch.encode()
            f.write(struct.pack(">IqqII", SYNC, k, ts, len(c), len(data)) + c + data)
