"""The embedded solvers' LU (``templates/bgm_lu.c``) inside the Jacobian's band: compiled with
bandwidths on the command line and checked against numpy on random banded matrices whose
elimination needs row interchanges, and on dense ones (band = the whole matrix)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

TEMPLATES = Path(__file__).resolve().parents[2] / "bgmodelica" / "fmi" / "templates"

DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
void bgm_iteration_matrix(double *m, const double *J, double coef, int n);
int bgm_lu_factor(double *a, int *piv, int n);
void bgm_lu_solve(const double *a, const int *piv, int n, double *b);
int main(void) {
    int n, i, j, swaps = 0;
    double coef;
    if (scanf("%d %lf", &n, &coef) != 2) return 2;
    double *J = malloc(sizeof(double) * n * n), *m = calloc((size_t)n * n, sizeof(double));
    double *b = malloc(sizeof(double) * n);
    int *piv = malloc(sizeof(int) * n);
    for (j = 0; j < n; j++)
        for (i = 0; i < n; i++)
            if (scanf("%lf", &J[i + j * n]) != 1) return 2;
    for (i = 0; i < n; i++)
        if (scanf("%lf", &b[i]) != 1) return 2;
    bgm_iteration_matrix(m, J, coef, n);
    if (bgm_lu_factor(m, piv, n)) return 3;
    bgm_lu_solve(m, piv, n, b);
    for (i = 0; i < n; i++) swaps += piv[i] != i;
    printf("%d\n", swaps);
    for (i = 0; i < n; i++) printf("%.17g\n", b[i]);
    return 0;
}
"""


def _compiler() -> str:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    return cc


@pytest.mark.parametrize("n,kl,ku", [(40, 2, 1), (40, 1, 3), (25, 0, 2), (30, 5, 5),
                                     (12, 11, 11)])
def test_band_lu_solves_like_numpy(tmp_path, n, kl, ku):
    driver = tmp_path / "driver.c"
    driver.write_text(DRIVER)
    exe = tmp_path / "lu"
    subprocess.run([_compiler(), "-O2", f"-DBGM_JAC_KL={kl}", f"-DBGM_JAC_KU={ku}", "-o",
                    str(exe), str(driver), str(TEMPLATES / "bgm_lu.c"), "-lm"], check=True)
    rng = np.random.default_rng(n + 100 * kl + 10 * ku)
    coef = 0.7
    for _ in range(5):
        jac = rng.standard_normal((n, n))
        i, j = np.indices((n, n))
        jac[(j - i > ku) | (i - j > kl)] = 0.0
        np.fill_diagonal(jac, 1.0 / coef + 1e-3 * rng.standard_normal(n))   # M's diagonal ~ 0
        b = rng.standard_normal(n)
        text = f"{n} {coef!r}\n" + " ".join(map(repr, jac.T.ravel().tolist())) + "\n" \
            + " ".join(map(repr, b.tolist()))
        out = subprocess.run([str(exe)], input=text, capture_output=True, text=True,
                             check=True).stdout.split()
        swaps, x = int(out[0]), np.array(out[1:], dtype=float)
        m = np.eye(n) - coef * jac
        expected = np.linalg.solve(m, b)
        assert np.max(np.abs(x - expected)) <= 1e-9 * max(1.0, np.max(np.abs(expected)))
        if kl > 0:
            assert swaps > 0                  # the pivoting inside the band was exercised
