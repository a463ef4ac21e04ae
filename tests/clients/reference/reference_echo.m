function reference_echo(varargin)
%REFERENCE_ECHO  A test law for the MATLAB/Octave controller library's reference
%(tests/clients/reference_law.py): each joint's effort is the r its reference has at the
%state answered, from the reference the library hands the law (ctl.reference); 0 for a
%joint without one. The harness checks every command in the daemon's log against the
%references it published.
ctl = lagsim_controller('reference_echo', 'MANIPULATOR', 'manipulator');
if ~ctl.start(varargin{:})
    return;
end
n = 0;
st = ctl.next_state();
while ~isempty(st)
    u = zeros(numel(st.name), 1);
    for k = 1:numel(st.name)
        j = ctl.joint(ctl.reference, st.name{k});
        if j > 0
            u(k) = ctl.reference.r(j);
        end
    end
    ctl.command(st.sim_time, st.name, u);
    n = n + 1;
    st = ctl.next_state();
end
ctl.finish(sprintf('states=%d', n));
end
