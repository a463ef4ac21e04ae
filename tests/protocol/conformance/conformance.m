function conformance(varargin)
%CONFORMANCE  The conformance controller in MATLAB/Octave, over the MATLAB/Octave client
%library (clients/octave/lagsim_controller.m): the conformance law, for
%tests/protocol/play.py.
%
%   octave --path BUILD/octave --path tests/protocol/conformance --eval "conformance('--prefix', P, '--url', URL)"
%
%   For each state the library hands it: u = -(kp q + kd qd) on each actuated joint of
%   the scene of that state's generation (kp, kd: the scene's parameters of those names),
%   one line "conformance: law generation=G sim_time=T" on stdout before the command goes
%   (docs/protocol.md, "Checking a binding of your own").
ctl = lagsim_controller('conformance', 'CONFORMANCE', 'dipc');
ctl.option('timeout', '60', 'wall s without a scene, or without any message once running');
if ~ctl.start(varargin{:})
    return;
end
laws = 0;
st = ctl.next_state();
while ~isempty(st)
    sc = ctl.scene;
    names = sc.joint_name;     % Java arrays: copied before indexing
    actuated = sc.actuated;
    kp = ctl.params.kp;
    kd = ctl.params.kd;
    cmd_names = {};
    u = [];
    for j = 1:numel(actuated)
        if actuated(j)
            i = ctl.joint(st, char(names(j)));
            cmd_names{end + 1} = char(names(j)); %#ok<AGROW>
            u(end + 1) = -(kp * st.position(i) + kd * st.velocity(i)); %#ok<AGROW>
        end
    end
    laws = laws + 1;
    ctl.say('conformance: law generation=%d sim_time=%.17g\n', st.generation, st.sim_time);
    ctl.command(st.sim_time, cmd_names, u);
    st = ctl.next_state();
end
ctl.finish(sprintf('laws=%d held=%d', laws, ctl.held));
end
