"""dtcosim physics core: pure numpy/scipy, SI units inside, no FMI.

Modules
-------
units, validation, errors   unit conversions from the paper, validators, exceptions
contact                     CFS (eq. 2-4) and impact (eq. 1) contact laws
stages, drivetrain, presets gear stages, shafts, topology, paper presets (Tables 3, 5, 6)
assembly                    bodies, mesh/shaft matrices, forces and analytic Jacobian
wind, generator             rotor-speed process (eq. 13-14), generator rotor and load events
reference                   monolithic LSODA reference solver and energy audit
acceleration                peak output-gear acceleration at every solver step (eq. 11)
cases                       the paper's reference cases (Tables 2, 4, 7; Fig. 10-11)
modes, modal_verification   linearisation, undamped/complex modes, free-response check
campbell                    natural frequencies over rotor speed vs 1P/3P and gear-mesh lines
fatigue, events             rainflow/DEL/LDD; contact-loss events per mesh
mesh_stiffness, spectrum    time-varying mesh stiffness; amplitude spectra and peaks
"""

__version__ = "0.1.0"
