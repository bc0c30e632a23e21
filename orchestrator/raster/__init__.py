"""The run figures' own renderer: line plots on Pillow, laid out and drawn once, without matplotlib.

The four figures of every ``dtcosim run`` (``rotor_speed.png``, ``generator_speed.png``,
``contact_forces.png``, ``load_duration.png``) are drawn here: importing matplotlib and
drawing them with it cost about 0.7 s of CPU, half of a whole run's (docs/performance.md:
``python benchmarks/bench_plots.py`` and ``bench_commands.py`` on main at 1988d3f), mostly
matplotlib's per-artist machinery (every tick an object of lines, texts and transforms) and
its import. This
package does only what those figures need: a grid of axes in fixed margins, linear and
log y axes with matplotlib's tick rules, grid, curves (solid, dashed), horizontal lines,
shaded spans, bars, notes, legends (the "best" corner or beside the axes), titles;
anti-aliased (curves and bars drawn four times finer and reduced), text through FreeType
in DejaVu Sans. Every other figure stays on matplotlib (:mod:`orchestrator.plotting`);
both write their PNGs with :func:`orchestrator.figure_files.write_png`.

Modules
-------
ticks    tick positions and labels (linear, log, offsets and powers of ten)
text     the font, text boxes, drawing text
paint    colours and pixels: boxes, snapped lines, clipped anti-aliased curves, masks
legend   legend entries, box, the "best" place
axes     one axes: content, limits, layout, drawing
figure   the grid of axes, margins, title, rendering, the PNG file
"""

