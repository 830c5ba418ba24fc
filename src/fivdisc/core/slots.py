"""Slots of the integrator's state arrays, its control vector, status codes and the
event table's columns: what :mod:`~fivdisc.core.integrate` and its callers share."""

# Status codes (``ist[I_STATUS]``).
ST_RUNNING = 0
ST_DONE = 1
ST_NONFINITE = 2
ST_UNDERFLOW = 3
ST_ZENO = 4
ST_MAX_SWITCHES = 5
ST_STOPPED = 6
# Set by the caller (fivdisc.engine.integration), not the kernel: the step budget is spent.
ST_TOO_MANY_STEPS = 7

# Integer state slots.
I_STATUS = 0
I_STEPS = 1
I_REJECTED = 2
I_RHS = 3
I_OUT_NEXT = 4
I_EVENTS = 5
I_SWITCHES = 6
I_ZENO = 7
I_STARTED = 8
I_EVAL_EVENTS = 9
# 1 (2 after a rejected step) when the last call ended on its step budget: the next call
# resumes the step-size controller where it was, so splitting a run changes no step.
I_PAUSED = 10
N_ISTATE = 11

# Float state slots.
F_T = 0
F_H = 1
F_LAST_SWITCH = 2
F_H_CAP = 3
# Largest |w| under the sliders at the samples written since the caller reset it.
F_W_PEAK = 4
# The step-size controller's previous error, kept across a paused call.
F_ERR_OLD = 5
N_FSTATE = 6

# Control slots.
C_RTOL = 0
C_ATOL = 1
C_MAX_STEP = 2
C_T_FINAL = 3
C_OUT_DT = 4
C_MAX_SWITCHES = 5
C_ZENO_DT = 6
C_ZENO_COUNT = 7
C_STOP_MASK = 8
# Steps (accepted and rejected) one call may try before it returns; <= 0: no bound.
C_CALL_STEPS = 9
N_CONTROL = 10

# Columns of the event table's integer part.
EVI_KIND = 0
EVI_FROM = 1
EVI_TO = 2
EVI_SLIDER = 3
N_EVI = 4
