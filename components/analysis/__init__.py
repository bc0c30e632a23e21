"""Analyses of a drivetrain and of its simulated time series.

Modules
-------
equilibrium             static equilibrium and linearisation at an operating point
eigen                   undamped and complex modes of any M, C, K
modes                   the drivetrain's modes: named bodies, energy shares, mode kinds
modal_verification      free response of the nonlinear model vs the linearised frequencies
campbell                natural frequencies over rotor speed vs 1P/3P and gear-mesh lines
fatigue                 rainflow, damage-equivalent loads, a run's fatigue report
load_duration           load duration/revolution distributions
contact_loss            separations, flank changes and time inside the backlash per mesh
spectrum                amplitude spectra and spectral peaks
gear_mesh, gear_rating  ISO 6336 mesh geometry, tooth stiffness and gear ratings
plausibility            a drivetrain's values judged by physics (a table of rules)
"""
