"""The monolithic reference: one stiff ODE of the whole drivetrain (LSODA, analytic Jacobian).

Modules
-------
solver          :func:`~components.reference.solver.simulate_monolithic`, solver settings, energy audit
results         sampled results and their window statistics
cases           the paper's reference cases (Tables 2, 4, 7; Fig. 10-11)
acceleration    peak output-gear acceleration at every solver step (eq. 11)
"""
