"""Published numbers from the thesis (Mantelli 2022), chapter 4, for side-by-side tables.

GREEDY: Tables 4.2-4.4, Greedy column: goal -> (mean, std) in metres.
SHORTEST: Tables 4.7-4.8; for Normal, Table 4.6 is held out of our copy of the thesis, so the
shortest path is the one implied by Table 4.10 (Greedy mean / percent of optimal; the semantic
row gives the same values to 0.01 m).
MAPS: reference map file stem -> (thesis name, authors' start (m), segmentation delta (m^2)).
"""

MAPS = {
    "par_impar_par_impar": ("Normal", (25.5, 28.5), 4.5),
    "par_impar_par_impar_inverse": ("Inverse", (25.5, 28.5), 4.5),
    "hotel2": ("Hotel", (46.0, 64.0), 2.5),
}

GREEDY = {
    "Normal": {54: (121.94, 41.59), 55: (132.68, 46.71), 111: (170.69, 70.15), 124: (148.50, 70.09)},
    "Inverse": {54: (98.88, 41.52), 55: (154.29, 54.78), 111: (200.16, 102.57), 124: (165.73, 82.65)},
    "Hotel": {76: (314.90, 131.74), 135: (433.75, 194.93), 148: (525.30, 167.12), 185: (167.09, 166.77)},
}

SHORTEST = {
    "Normal": {54: 121.94 / 7.0937, 55: 132.68 / 4.9745, 111: 170.69 / 4.5602, 124: 148.50 / 4.4783},
    "Inverse": {54: 7.65, 55: 15.98, 111: 40.67, 124: 24.65},
    "Hotel": {76: 63.16, 135: 72.51, 148: 75.81, 185: 52.53},
}
