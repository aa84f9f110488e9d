"""The Dormand-Prince 5(4) Runge-Kutta pair and Shampine's continuous extension, as data.

Dormand & Prince, J. Comput. Appl. Math. 6(1):19-26, 1980 (the tableau, "RK5(4)7M", first
same as last); Shampine, Math. Comp. 46(173):135-150, 1986 (the 4th-order dense output). For
an ODE z' = f(t, z) and a step h from (t, z):

    k_1 = f(t, z),   k_s = f(t + C[s] h, z + h sum_j A[s][j] k_j)        (s = 2 .. 7)
    z_new = z + h sum_s B[s] k_s          (5th order; k_7 = f(t + h, z_new), FSAL)
    err   = h sum_s E[s] k_s              (5th minus 4th order: the error estimate)
    z(t + theta h) = z + h sum_s k_s sum_q P[s][q] theta^(q + 1)        (0 <= theta <= 1)

The same coefficients as scipy.integrate.RK45 (tests/test_dormand_prince.py compares them).
The kernels (dynamics.kernels) use them through these names, each row a tuple of floats (a
compile-time constant for numba); ``A`` lists the rows from stage 2 on (A[s - 2]).
"""

from __future__ import annotations

import numpy as np

#: nodes c_s of stages 1..7 (fraction of the step)
C = (0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0)
#: stage coefficients a_sj, stages 2..6 (stage 7 is z_new itself: its row is B)
A2 = (1 / 5,)
A3 = (3 / 40, 9 / 40)
A4 = (44 / 45, -56 / 15, 32 / 9)
A5 = (19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729)
A6 = (9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656)
A = (A2, A3, A4, A5, A6)
#: 5th-order weights b_s (stages 1..6; b_2 = 0 and b_7 = 0)
B = (35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84)
#: error weights e_s = b_s - b*_s (stages 1..7)
E = (-71 / 57600, 0.0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525, 1 / 40)
#: Shampine's dense-output matrix (7 stages x powers theta^1..theta^4)
P = np.array(
    [
        [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
        [0, 0, 0, 0],
        [0, 131558114200 / 32700410799, -68118460800 / 10900136933, 87487479700 / 32700410799],
        [0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
        [0, 127303824393 / 49829197408, -318862633887 / 49829197408, 701980252875 / 199316789632],
        [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
        [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
    ]
)
P.flags.writeable = False
