"""The stepping loop: one plan of a communication step, two executors of it.

Modules
-------
plan             :class:`~.plan.StepPlan` (per FMU: its calls, value references, input feeds with their
                 source columns and transformations, output columns) and :class:`~.plan.RowBuffers`
python_loop      the plan executed in plain Python (any FMU, typed ports, algebraic loops, profiling)
compiled_loop    the same plan executed by a compiled block (PythonFMUs with Real variables only)
compiled_block   the numba source of that block (compiled ahead of time into the user cache)
compiled_layout  the columns of the plan arrays the compiled block reads
"""
