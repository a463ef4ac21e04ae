#!/usr/bin/env python3
"""Every class in lagsim's jars is of the release the build asks for (LAGSIM_JAVA_RELEASE,
8 by default: class version 52), so that MATLAB's bundled Java 8 loads them.

    java_release.py RELEASE JAR...
"""
import struct
import sys
import zipfile

release, jars = int(sys.argv[1]), sys.argv[2:]
bad = 0
for jar in jars:
    n = 0
    with zipfile.ZipFile(jar) as z:
        for name in z.namelist():
            if not name.endswith(".class"):
                continue
            magic, _minor, major = struct.unpack(">IHH", z.read(name)[:8])
            n += 1
            if magic != 0xCAFEBABE or major != 44 + release:
                print("FAIL: %s: %s is class version %d, not %d (Java %d)"
                      % (jar, name, major, 44 + release, release))
                bad += 1
    print("%s: %d classes checked" % (jar, n))
    if n == 0:
        print("FAIL: %s holds no class" % jar)
        bad += 1
sys.exit(1 if bad else 0)
