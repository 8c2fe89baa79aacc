"""The report's figures, re-exported: they now live in :mod:`.figures` (report/figures/), one
module per kind of figure (:mod:`.figures.common` the paper style and the shared drawing
helpers, :mod:`.figures.paths`, :mod:`.figures.distances`, :mod:`.figures.replay`,
:mod:`.figures.objects`, :mod:`.figures.chain`, :mod:`.figures.indirect`). Every name this
module had is still here, so ``from semsearch_cli.report.plots import plot_boxes`` keeps working.

Every figure is written by ``figures.common._save``: to intercept the figures, patch it there
(patching ``plots._save`` changes nothing).
"""

from __future__ import annotations

from .figures.common import (_HALO, CHAR_W, COLUMN_IN, EVERY_RUN_LW, GOAL_COLOR, IMAGE_FORMATS, LABEL_PAD, LINE_H,  # noqa: F401
                             PALETTE, PAPER_RC, PNG_DPI, STAR_BOX_PT, STAR_PT, STOP_LABEL_AT, _animate, _axes_m_per_pt,
                             _cell, _draw_map, _extent, _grid, _label_outer, _legend, _linestyle, _map_axes,
                             _n_by_planner, _no_finite, _number_layout, _number_signs, _outer_y, _overlap, _paper,
                             _places, _save, _sign_labels, _starts, _stops, _text_box, episode_mean, every_run_alpha,
                             image_formats, map_image, place_stop_labels, planner_colors, thin_boxes)
from .figures.paths import plot_path_panels, plot_scenario  # noqa: F401
from .figures.distances import (_HORIZONTAL, BUDGET_PAD, _to_limit, budget_curve, budget_limit, plot_alpha_sweep,  # noqa: F401
                                plot_boxes, plot_budget, plot_sweep, swept_rows, swept_values)
from .figures.replay import REPLAY_NUMBER_PT, _sign_at, animate_run, draw_replay_frame, replay_figure  # noqa: F401
from .figures.objects import plot_heat, plot_heat_steps, plot_object_bars  # noqa: F401
from .figures.chain import plot_chain_stages  # noqa: F401
from .figures.indirect import animate_probability, plot_rooms, plot_success_by_scale  # noqa: F401
