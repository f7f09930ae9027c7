"""Energy of one operation on 45 nm CMOS (Horowitz 2014), the paper's hardware assumption (Sec. 4.2).

A multiply-accumulate (MAC) of a real-valued layer costs a 32-bit float multiply (3.7 pJ) plus an add
(0.9 pJ); a synaptic operation (SOP) of a spike-driven layer is one add, because a binary spike selects a
weight instead of multiplying it. The profile's ``energy.e_mac_pj`` / ``energy.e_ac_pj`` override them.
"""

from __future__ import annotations

#: Horowitz (2014), 45 nm, 32-bit float: multiply 3.7 pJ + add 0.9 pJ (pJ per MAC).
E_MAC_PJ = 4.6
#: Horowitz (2014), 45 nm, 32-bit float add (pJ per accumulate / synaptic operation).
E_AC_PJ = 0.9


def energy_uj(macs: float, sops: float, e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ) -> float:
    """``E = E_MAC * MACs + E_AC * SOPs``, converted from pJ to µJ.

    Parameters
    ----------
    macs, sops : float
        Multiply-accumulates and synaptic operations (ops, per prediction).
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ.

    Returns
    -------
    float
        Energy, µJ (per prediction when the counts are).
    """
    return (e_mac * macs + e_ac * sops) * 1e-6
