"""Reference p-values for coordinator/src/stats.rs, from SciPy.

    python -m venv .venv && .venv/bin/pip install scipy
    .venv/bin/python coordinator/studies/tests/reference/wilcoxon_reference.py
"""
import scipy
from scipy.stats import wilcoxon

print("scipy", scipy.__version__)
for d in ([1.5, -0.3, 2.2, 0.7, -1.1, 3.4, 0.9, 1.8, -0.2, 2.5, 0.4, 1.1],
          [1.0, 1.0, -1.0, 2.0, 2.0, 0.0, 3.0, -2.0, 1.0, 0.0]):
    print(repr(wilcoxon(d, zero_method="wilcox", correction=False, method="approx").pvalue))
