package lagsim.examples;

import lagsim.control_t;
import lagsim.joint_command_t;

/**
 * lagsim's outgoing messages built from plain numbers and strings, for callers whose Java
 * bridge cannot fill every field of lcm-gen's types: GNU Octave 7 cannot set a byte field
 * (control_t.request: "Can not set byte field ... to null value") and hands a
 * one-element vector to a double[] field as an empty array. The MATLAB and GNU Octave
 * controllers (clients/octave) build their commands and control requests here:
 *
 * <pre>
 *     cmd = javaMethod('command', 'lagsim.examples.Messages', st.generation, st.sim_time, {'theta0'}, u);
 *     lc.publish('DIPC_COMMAND', cmd);
 * </pre>
 *
 * Every message is stamped with the wall clock (utime, microseconds since 1970).
 */
public final class Messages {
    private Messages() {}

    private static long now() { return System.currentTimeMillis() * 1000; }

    /** A command answering the state of generation {@code generation} at {@code simTime}
     *  (a state is known by both: docs/server.md): {@code efforts[k]} for joint
     *  {@code names[k]} (N or N m). Arrays of different lengths throw IllegalArgumentException.
     *  The generation is a double, as MATLAB and Octave hand numbers over (exact to 2^53). */
    public static joint_command_t command(double generation, double simTime, String[] names,
                                          double[] efforts) {
        if (names.length != efforts.length || names.length > Short.MAX_VALUE)
            throw new IllegalArgumentException(names.length + " names for " + efforts.length + " efforts");
        joint_command_t cmd = new joint_command_t();
        cmd.utime = now();
        cmd.sim_time = simTime;
        cmd.generation = (long) generation;
        cmd.num_joints = (short) names.length;
        cmd.name = names.clone();
        cmd.effort = efforts.clone();
        return cmd;
    }

    /** A command for one joint (a one-element vector reaches Java as a scalar). */
    public static joint_command_t command(double generation, double simTime, String name,
                                          double effort) {
        return command(generation, simTime, new String[] {name}, new double[] {effort});
    }

    /** A control request without arguments: control_t.DESCRIBE, PAUSE, RESUME, STATUS ... */
    public static control_t control(int request) {
        control_t req = new control_t();
        req.utime = now();
        req.request = (byte) request;
        req.q = new double[0];
        req.qd = new double[0];
        req.key = "";
        req.value = "";
        return req;
    }
}
