import lagsim.examples.Controller;
import lagsim.joint_state_t;
import lagsim.reference_t;

/**
 * A test law for the Java controller library's reference (tests/clients/reference_law.py):
 * each joint's effort is the r its reference has at the state answered, from the
 * reference the library hands the law (Controller.reference()); 0 for a joint without one.
 * The harness checks every command in the daemon's log against the references it published.
 */
public final class ReferenceEcho {
    private ReferenceEcho() {}

    public static void main(String[] args) throws Exception {
        Controller ctl = new Controller("ReferenceEcho", "MANIPULATOR", "manipulator");
        ctl.start(args);
        joint_state_t st;
        long n = 0;
        while ((st = ctl.nextState()) != null) {
            reference_t ref = ctl.reference();
            double[] u = new double[st.num_joints];
            for (int k = 0; k < st.num_joints; k++) {
                int j = Controller.joint(ref, st.name[k]);
                u[k] = j >= 0 ? ref.r[j] : 0.0;
            }
            ctl.command(st.sim_time, st.name, u);
            n++;
        }
        System.exit(ctl.finish("states=" + n));
    }
}
