"""The drivetrain model: everything a dtcosim FMU carries (numpy and scipy.linalg only).

Modules
-------
contact                     CFS (eq. 2-4) and impact (eq. 1) contact laws
mesh_stiffness              time-varying mesh stiffness (mesh phasing, stiffness factor)
stages, drivetrain          gear stages and shafts, the drivetrain topology
presets                     the paper's parameter sets (Tables 3, 5, 6; Sec. 4.1 variant)
parameter_map               flat parameter names <-> drivetrain (shared with FMUs and scenarios)
assembly                    bodies, mesh/shaft matrices, forces and analytic Jacobian
integrators                 Rosenbrock W-method with step control
gearbox_model               the gearbox side of the co-simulation cut (the Gearbox FMU's model)
generator, wind             generator rotor and load events; rotor-speed process (eq. 13-14)
signals                     unit and kind of each model variable (Gearbox FMU outputs, reference series)

Nothing here imports :mod:`components.reference` or :mod:`components.analysis`.
"""
