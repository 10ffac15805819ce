"""The report panels of the tooth pair's stiffness, the same at torsional and contact3d: k(theta1) over one mesh cycle
(wormsim.tooth.mesh_stiffness's TCA with the run's k', and the loaded tooth contact analysis's secant k at the
working torque where the run uses the teeth's compliance, wormsim.tooth.ltca) and the load share of each wheel tooth
over the mesh cycle (the LTCA's)."""

from __future__ import annotations

import numpy as np


def draw_mesh_stiffness(a, ms, lt=None) -> None:
    """k on the line of action over the worm angle in the mesh cycle: TCA both flank sides, the LTCA where given."""
    deg = np.degrees(ms.theta1_rad)
    a.plot(deg, ms.k_mesh_fwd_n_per_m, "o-", ms=3, label=f"TCA, flank side +1 (k' {ms.stiffness_source})")
    a.plot(deg, ms.k_mesh_rev_n_per_m, "s--", ms=3, label="TCA, flank side -1")
    if lt is not None:
        a.plot(
            np.degrees(lt.theta1_rad),
            lt.mesh_stiffness_n_per_m,
            "^-",
            ms=3,
            label=f"loaded TCA at {lt.torque_nm:.3g} N m (teeth' compliance)",
        )
    a.set_xlabel("worm angle in the mesh cycle [deg]")
    a.set_ylabel("k on the line of action [N/m]")
    a.set_title(f"mesh stiffness k(theta1), mean {np.mean(ms.k_mesh_fwd_n_per_m):.3g} N/m")
    a.legend(fontsize=8)


def draw_load_shares(a, lt, source: str) -> None:
    """The LTCA's load share of each wheel tooth over the mesh cycle; without an LTCA a note why."""
    if lt is None:
        a.text(
            0.5,
            0.5,
            f"load shares: from the teeth's compliance\n(this run's stiffness: {source};\n"
            "contact.stiffness_n_per_m unset and stiffness_model teeth give them)",
            ha="center",
            va="center",
            transform=a.transAxes,
            fontsize=9,
        )
        a.set_axis_off()
        return
    deg = np.degrees(lt.theta1_rad)
    share = np.asarray(lt.load_share)
    for j in range(share.shape[1]):
        if np.any(share[:, j] > 0):
            a.plot(deg, share[:, j], "o-", ms=3, label=f"tooth {j}")
    a.set_ylim(0, 1.05)
    a.set_xlabel("worm angle in the mesh cycle [deg]")
    a.set_ylabel("share of the wheel torque")
    a.set_title(
        f"load share per wheel tooth (loaded TCA, {lt.torque_nm:.3g} N m): max {np.max(share):.2f}, "
        f"teeth in contact {np.mean(lt.teeth_in_contact):.2f}"
    )
    a.legend(fontsize=7, ncol=3)
