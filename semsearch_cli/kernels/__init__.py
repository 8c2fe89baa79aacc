"""Pure array kernels (numba / numpy / SciPy): grid searches and flood fills, ray casting and
HIMM, the harmonic potential. They know nothing of robots, tasks or plots."""
