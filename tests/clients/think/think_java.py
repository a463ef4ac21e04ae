#!/usr/bin/env python3
"""A slow control law for a Java controller run as written:

    think_java.py BUILD java -cp {think}:CLASSPATH... MAIN ARGS...

Compiles into a fresh directory a lagsim.joint_command_t whose constructor takes
LAGSIM_THINK_S wall seconds first (and appends a line to the file LAGSIM_THINK_LOG, if
set): lcm-gen's own source (BUILD/lcmtypes/java/src) with that sleep in its constructor
(think.py says why the constructor). Then runs the command with {think} replaced by that
directory: first on the class path, it stands in for the types jar's class. Nothing else
of the program changes.
"""
import os
import subprocess
import sys
import tempfile


def think_classes(build, out_dir):
    """Writes and compiles the slow joint_command_t under out_dir; returns out_dir."""
    src = open(os.path.join(build, "lcmtypes", "java", "src", "lagsim",
                            "joint_command_t.java")).read()
    plain = "public joint_command_t()\n    {\n    }"
    if plain not in src:
        sys.exit("think_java.py: lcm-gen's Java constructor changed")
    src = src.replace(plain, "public joint_command_t()\n    {\n        try {"
                      " String log = System.getenv(\"LAGSIM_THINK_LOG\");"
                      " if (log != null) java.nio.file.Files.write(java.nio.file.Paths.get(log),"
                      " \"law\\n\".getBytes(), java.nio.file.StandardOpenOption.CREATE,"
                      " java.nio.file.StandardOpenOption.APPEND);"
                      " Thread.sleep((long)(1000 * Double.parseDouble(System.getenv("
                      "\"LAGSIM_THINK_S\")))); }"
                      " catch (Exception e) { }\n    }")
    os.makedirs(os.path.join(out_dir, "lagsim"), exist_ok=True)
    path = os.path.join(out_dir, "lagsim", "joint_command_t.java")
    with open(path, "w") as f:
        f.write(src)
    subprocess.run(["javac", "-nowarn", "-cp", "/usr/share/java/lcm.jar", "-d", out_dir, path],
                   check=True)
    return out_dir


def main():
    build, cmd = sys.argv[1], sys.argv[2:]
    d = think_classes(build, tempfile.mkdtemp(prefix="lagsim_think_java_"))
    cmd = [c.replace("{think}", d) for c in cmd]
    os.execvp(cmd[0], cmd)


if __name__ == "__main__":
    main()
