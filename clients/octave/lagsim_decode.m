function msg = lagsim_decode(data, type)
%LAGSIM_DECODE  The lagsim message of type TYPE ('joint_state_t', 'reference_t',
%'event_t', 'scene_t', 'status_t', ...) in DATA, the bytes of a received message (int8, as
%lcm.lcm.MessageAggregator's message.data gives them), or [] when they do not decode
%whole.
%
%   m = agg.getNextMessage(100);
%   st = lagsim_decode(m.data, 'joint_state_t');   % a lagsim.joint_state_t, or []
%
%   Decoded by lagsim's bounded Java decoder (lagsim.examples.BoundedInput): a string
%   length is checked before anything is allocated for it (lcm-gen's own decoder
%   allocates a forged length of 2^31-1 first), and only a message that encodes back to
%   the very bytes received, every number finite, no string with a NUL inside, is kept.
%   No bytes at all are no message: [] (Octave would hand Java a null array).
msg = [];
if isempty(data)
    return;
end
msg = javaMethod('tryDecode', 'lagsim.examples.BoundedInput', data, ['lagsim.' type]);
end
