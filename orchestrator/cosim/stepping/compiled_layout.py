"""Column layout of the plan arrays shared by :mod:`.compiled_loop` and :mod:`.compiled_block`."""

# columns of the per-slot plan table (int64): FMI function addresses, the component, value references
# and their counts, the slot's input buffer, its first output column's byte offset, its feeds
(P_DO_STEP, P_SET_REAL, P_GET_REAL, P_COMPONENT, P_IN_VR, P_N_IN, P_IN_BUF, P_OUT_VR, P_N_OUT, P_N_COUPLE,
 P_OFFSET, P_FEED_FIRST, P_FEED_END) = range(13)
N_PLAN = 13
# columns of the per-feed table (int64): input index in the plan's input buffer, source column, source already
# stepped in this step (Gauss-Seidel), transformed connection; the float table holds (factor, offset)
F_INPUT, F_COLUMN, F_UPSTREAM, F_TRANSFORMED = range(4)
#: function codes of a failing call (returned to Python, which raises StepFailed)
FUNCTIONS = ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal")
