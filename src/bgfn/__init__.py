"""BGFN: a brain-inspired GPS/INS fusion network, reproduced.

Subpackages follow the paper's structure:

- :mod:`bgfn.nav`   -- Earth model, strapdown INS, 15-state loosely coupled Kalman filter (paper Sec. 2).
- :mod:`bgfn.data`  -- the NaveGo Turin drive: acquisition, simulation of IMU/GNSS, datasets.
- :mod:`bgfn.models` -- BGFN (spiking Transformer) and the baselines (paper Sec. 3).
"""

__version__ = "0.1.0"
