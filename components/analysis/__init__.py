"""Analyses of a drivetrain and of its simulated time series.

Modules
-------
modes                   static equilibrium, linearisation, undamped/complex modes
modal_verification      free response of the nonlinear model vs the linearised frequencies
campbell                natural frequencies over rotor speed vs 1P/3P and gear-mesh lines
fatigue                 rainflow, damage-equivalent loads, load duration/revolution distributions
contact_loss            separations, flank changes and time inside the backlash per mesh
spectrum                amplitude spectra and spectral peaks
"""
