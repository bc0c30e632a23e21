"""dtcosim physics core: pure numpy/scipy, SI units inside, no FMI.

Imports go one way: ``analysis`` -> ``reference`` -> ``model`` -> the base modules.

Base modules
------------
errors, units, validation   exceptions, unit conversions from the paper, validators

Subpackages
-----------
model       what the FMUs carry: contact laws, stages, drivetrain, presets, parameter map,
            assembly, integrators, the co-simulation gearbox model, generator, wind
reference   the monolithic reference solver, its results, the paper's cases, eq. 11
analysis    modes (equilibrium, eigen, modes), modal verification, Campbell, fatigue,
            contact loss, spectra
"""

__version__ = "0.1.0"
