import lagsim.examples.Controller;
import lagsim.joint_state_t;
import lagsim.scene_t;

/**
 * The conformance controller in Java, over the Java client library
 * (lagsim.examples.Controller): the conformance law, for tests/protocol/play.py.
 *
 * <pre>
 *   java -cp lcm.jar:lagsim_types.jar:lagsim_examples.jar:CLASSES Conformance --prefix P --url URL
 * </pre>
 *
 * For each state the library hands it: u = -(kp q + kd qd) on each actuated joint of the
 * scene of that state's generation (kp, kd: the scene's parameters of those names), one
 * line "conformance: law generation=G sim_time=T" on stdout before the command goes
 * (docs/protocol.md, "Checking a binding of your own").
 */
public final class Conformance {
    private Conformance() {}

    public static void main(String[] args) throws Exception {
        Controller ctl = new Controller("Conformance", "CONFORMANCE", "dipc");
        ctl.option("timeout", "60", "wall s without a scene, or without any message once running");
        ctl.start(args);
        int laws = 0;
        joint_state_t st;
        while ((st = ctl.nextState()) != null) {
            scene_t sc = ctl.scene;
            double kp = ctl.params.get("kp"), kd = ctl.params.get("kd");
            int n = 0;
            for (int j = 0; j < sc.num_joints; j++) n += sc.actuated[j] ? 1 : 0;
            String[] names = new String[n];
            double[] u = new double[n];
            n = 0;
            for (int j = 0; j < sc.num_joints; j++) {
                if (!sc.actuated[j]) continue;
                int i = Controller.joint(st, sc.joint_name[j]);
                names[n] = sc.joint_name[j];
                u[n++] = -(kp * st.position[i] + kd * st.velocity[i]);
            }
            laws++;
            System.out.println("conformance: law generation=" + st.generation + " sim_time="
                               + Double.toString(st.sim_time));
            System.out.flush();
            ctl.command(st.sim_time, names, u);
        }
        System.exit(ctl.finish("laws=" + laws + " held=" + ctl.held));
    }
}
