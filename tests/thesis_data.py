"""Printed values from Gnilka (1971), copied from the OCR text of the thesis
(../shared/seeds/000_f4bfa46329200fb9.txt). Each array names its figure.

Only the upper triangles of the printed damping matrices are used: the
matrices are symmetric, and the OCR lost the minus sign on some lower-triangle
entries (e.g. Fig. 6.8 prints C(1,4) = 1.72 and C(4,1) = -1.72).
"""

import numpy as np

# Fig. 6.1: natural frequencies of the full eight-coordinate system (rocker open), x 1e3 rad/s.
FIG_6_1_OMEGA = np.array([0.0, 0.886, 63.6, 77.86, 149.8, 263.8, 638.7, 1371.1]) * 1e3
# Fig. 6.2: natural frequencies of the reduced seven-coordinate system (rocker in contact).
FIG_6_2_OMEGA = np.array([0.691, 25.9, 73.6, 146.7, 247.1, 521.9, 1070.2]) * 1e3
# Fig. 6.2, first mode shape column (mass-normalised), coordinates q1..q7.
FIG_6_2_MODE_1 = np.array([28.96, 28.95, -28.95, -43.37, -28.90, -28.93, 43.37])

# Fig. 6.8: configuration III (rocker in contact, 7 x 7): SYSM, DAMP, STF.
FIG_6_8_M = np.array([
    [1.55e-04, 7.77e-05, 0.0, 0.0, 0.0, 0.0, 0.0],
    [7.77e-05, 2.32e-04, 1.09e-05, 0.0, 0.0, -6.42e-06, 0.0],
    [0.0, 1.09e-05, 1.97e-06, 0.0, 0.0, -1.48e-06, 0.0],
    [0.0, 0.0, 0.0, 2.01e-04, -2.44e-05, 1.44e-05, -2.59e-05],
    [0.0, 0.0, 0.0, -2.44e-05, 6.66e-06, -5.00e-06, 0.0],
    [0.0, -6.42e-06, -1.48e-06, 1.44e-05, -5.00e-06, 8.64e-06, 0.0],
    [0.0, 0.0, 0.0, -2.59e-05, 0.0, 0.0, 5.18e-05],
])
FIG_6_8_C_UPPER = np.array([
    [2.48, 1.05, -7.37e-03, 1.72, -1.60e-01, 9.80e-02, -6.62e-01],
    [0, 3.49, 3.58e-01, 2.09, -3.08e-01, 3.16e-01, -6.69e-01],
    [0, 0, 2.03e-01, 1.02e-01, -3.48e-02, 2.59e-03, -1.65e-02],
    [0, 0, 0, 3.10, -4.83e-01, 3.25e-02, 2.99e-01],
    [0, 0, 0, 0, 2.86e-01, -8.02e-02, -5.40e-02],
    [0, 0, 0, 0, 0, 4.91e-01, 2.90e-02],
    [0, 0, 0, 0, 0, 0, 1.17],
])
FIG_6_8_K = np.array([
    [2.36e05, -2.36e05, 0.0, 0.0, 0.0, 0.0, 0.0],
    [-2.36e05, 2.53e06, 1.15e06, 0.0, 0.0, 1.15e06, 0.0],
    [0.0, 1.15e06, 7.63e05, 0.0, 0.0, 3.82e05, 0.0],
    [0.0, 0.0, 0.0, 1.39e06, -5.09e05, -5.09e05, 7.07e05],
    [0.0, 0.0, 0.0, -5.09e05, 5.09e05, 2.54e05, 0.0],
    [0.0, 1.15e06, 3.82e05, -5.09e05, 2.54e05, 1.27e06, 0.0],
    [0.0, 0.0, 0.0, 7.07e05, 0.0, 0.0, 7.07e05],
])

# Fig. 6.13: configuration V (cam in contact, rocker open): DAMP over q2..q8
# (q1 is eliminated by the cam contact). Upper triangle of the q2..q7 block;
# the pushrod's q8 diagonal (0.605) is printed in Fig. 6.16 and its coupling to
# q1 (-0.605) in the column damping of Fig. 6.14.
FIG_6_13_C_UPPER_Q2_Q7 = np.array([
    [1.32, 2.93e-01, 5.54e-01, -1.69e-01, 2.49e-01, -7.00e-02],
    [0, 1.42e-01, 1.00e-01, -3.70e-02, 2.01e-02, -1.01e-02],
    [0, 0, 1.51, -3.36e-01, -5.39e-02, 9.12e-01],
    [0, 0, 0, 2.71e-01, -6.93e-02, -1.09e-01],
    [0, 0, 0, 0, 4.69e-01, 5.66e-02],
    [0, 0, 0, 0, 0, 9.31e-01],
])
FIG_6_16_C_Q8_Q8 = 6.05e-01
FIG_6_14_C_Q8_Q1 = -6.05e-01

# Appendix E sample printout, 11,000 RPM run: "XZERO= 8.8245022D-01 FZERO = 5.0185073D 02".
XZERO = 0.88245022
FZERO = 501.85073
