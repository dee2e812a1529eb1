#!/usr/bin/python3
"""Writes the technology tables of the nodes below 45 nm (32, 22, 14, 10, 7 nm) from 45nm.tech.yaml
and Stillmaker & Baas's published scaling [SB17], every derived number with its factor and source.

    /usr/bin/python3 hw_model/tech/scale_tech.py          # rewrites hw_model/tech/{32,22,14,10,7}nm.tech.yaml
    /usr/bin/python3 hw_model/tech/scale_tech.py --check  # exit 1 if a shipped table differs

[SB17] A. Stillmaker, B. Baas, "Scaling equations for the accurate prediction of CMOS device
performance from 180 nm to 7 nm", Integration 58 (2017) 74-81: polynomial fits of delay (cubic in
Vdd) and energy (quadratic in Vdd) per node and device type, and a table of area factors between
nodes. The coefficients below are SB17's, as transcribed in UCLA NanoCAD's nodeScale
(github.com/wromaszkan/nodeScale, nodeScale.py: depCoeffDict, areaDict) and, for the energy fits
and the area table, identically in Accelergy's hwcomponents (scaling/techscaling.py); the
authors' erratum (vcl.ece.ucdavis.edu/pubs/2017.02.VLSIintegration.TechScale) quotes the HP 32 nm
and 65 nm energy rows of its Table 5 with the same values. SB17 states its fits' accuracy as a
coefficient of determination R^2 > 0.95; its area factors are printed to two significant figures.
"""

import argparse
import pathlib
import sys

import yaml

HERE = pathlib.Path(__file__).resolve().parent

# Delay fit d(V) = a V^3 + b V^2 + c V + d and energy fit e(V) = a V^2 + b V + c, per node and
# device type ([SB17] Tables 4 and 5). Bulk below 65 nm has high-performance (HP) and low-power
# (LP) rows; 20 nm and below are FinFET (PTM-MG) rows.
DELAY = {
    "130": (-76.65, 334.9, -493.4, 275.8),
    "90": (-60.34, 262.5, -384.2, 210.9),
    "HP45": (-501.6, 1567, -1619, 566.1),
    "HP32": (-1047, 2982, -2797, 873.5),
    "HP20": (0, 34.63, -66.37, 41.15),
    "HP14": (-40.66, 109.2, -100.6, 35.92),
    "HP10": (-34.95, 93.65, -85.99, 30.4),
    "HP7": (-28.58, 76.6, -70.26, 24.69),
}
ENERGY = {
    "90": (4.762, -4.781, 2.092),
    "LP45": (1.103, -0.362, 0.2767),
    "LP32": (0.9559, -0.7823, 0.471),
    "HP20": (0.373, -0.1582, 0.04104),
    "HP14": (0.2363, -0.09675, 0.02239),
    "HP10": (0.2068, -0.09311, 0.02375),
    "HP7": (0.1776, -0.09097, 0.02447),
}
# [SB17] area table, the 45 nm row: area at node N / area at 45 nm.
AREA_VS_45 = {"90": 2.8, "32": 0.46, "20": 0.21, "14": 0.17, "10": 0.1, "7": 0.059}

# Published 6T SRAM bit cells (um2): the high-density cell of each process paper.
BITCELL = {
    "45": (0.346, "Intel 45 nm, Mistry et al., IEDM 2007"),
    "32": (0.171, "Intel 32 nm, Natarajan et al., IEDM 2008"),
    "22": (0.092, "Intel 22 nm, Auth et al., VLSI Technology 2012"),
    "14": (0.0588, "Intel 14 nm, Natarajan et al., IEDM 2014"),
    "10": (0.0312, "Intel 10 nm, Auth et al., IEDM 2017"),
    "7": (0.027, "TSMC N7, Wu et al., IEDM 2016"),
}

# Which fits stand for a node, at which supply voltage. Energy: the rows Accelergy's
# hwcomponents uses (LP at 45 and 32 nm, HP below; the existing 90 and 45 nm tables are derived
# with its LP 45 nm row). Delay: HP rows (a clock is a high-performance design; the LP 45 nm row
# is slower than the 90 nm row). Voltages: each node's nominal Vdd, the PTM model's (PTM 32 nm:
# 0.9 V; PTM-MG 20/14/10/7 nm: 0.9/0.8/0.75/0.7 V); 45 nm at the 45 nm table's 0.9 V
# (Horowitz's point); 90 nm at the 90 nm table's 1.2 V.
# 22 nm is not a node of [SB17]: its factors are interpolated 10/12 of the way from 32 to 20 nm,
# linearly in the node, as hwcomponents interpolates a node it does not list.
NODES = {
    "90": dict(delay=["90"], energy=["90"], vdd=1.2),
    "45": dict(delay=["HP45"], energy=["LP45"], vdd=0.9),
    "32": dict(delay=["HP32"], energy=["LP32"], vdd=0.9),
    "22": dict(delay=["HP32", "HP20"], energy=["LP32", "HP20"], vdd=0.9, toward=10 / 12),
    "14": dict(delay=["HP14"], energy=["HP14"], vdd=0.8),
    "10": dict(delay=["HP10"], energy=["HP10"], vdd=0.75),
    "7": dict(delay=["HP7"], energy=["HP7"], vdd=0.7),
}
TARGETS = ["32", "22", "14", "10", "7"]


def poly(coefficients, v):
    out = 0.0
    for c in coefficients:
        out = out * v + c
    return out


def fit(table, node):
    """A node's fitted value (delay or energy) at its voltage; interpolated for 22 nm."""
    n = NODES[node]
    rows = n["delay" if table is DELAY else "energy"]
    values = [poly(table[r], n["vdd"]) for r in rows]
    if len(values) == 1:
        return values[0]
    t = n["toward"]
    return (1 - t) * values[0] + t * values[1]


def area_vs_45(node):
    if node == "22":
        t = NODES["22"]["toward"]
        return (1 - t) * AREA_VS_45["32"] + t * AREA_VS_45["20"]
    return AREA_VS_45[node]


def delay_vs_90(node):
    return fit(DELAY, node) / fit(DELAY, "90")


def delay_130_vs_90():
    return poly(DELAY["130"], 1.3) / fit(DELAY, "90")


def energy_vs_45(node):
    return fit(ENERGY, node) / fit(ENERGY, "45")


def sig(x, digits=4):
    """x to `digits` significant figures, as short text."""
    return f"{float(f'{x:.{digits}g}'):g}" if abs(x) >= 1e-4 else f"{x:.{digits}g}"


def fit_text(kind, node):
    n = NODES[node]
    rows = n["delay" if kind == "delay" else "energy"]
    if len(rows) == 1:
        return f"{rows[0]} {kind} fit at {n['vdd']} V"
    return f"{kind}: 1/6 x {rows[0]} + 5/6 x {rows[1]} fits at {n['vdd']} V"


def table_text(node, base):
    """The YAML text of one node's table, derived from the 45 nm table `base` (parsed)."""
    e, a = energy_vs_45(node), area_vs_45(node)
    cell, cell_source = BITCELL[node]
    cell45, cell45_source = BITCELL["45"]
    s = cell / cell45
    leak_logic = e / a
    ef, af, sf, lf = sig(e), sig(a), sig(s), sig(leak_logic)
    interpolated = node == "22"
    head = [
        f"# {node} nm, {NODES[node]['vdd']} V: the 45 nm table (45nm.tech.yaml) scaled by [SB17].",
        "# Generated by hw_model/tech/scale_tech.py from 45nm.tech.yaml; edit the script, not this file.",
        "#",
        "# Sources: [CACTI], [FIT], [H14], [ALD] as in 90nm.tech.yaml, through 45nm.tech.yaml;",
        "#  [SB17]  Stillmaker & Baas, Integration 58 (2017) 74-81: delay and energy fits per node",
        "#          (Tables 4, 5; as transcribed in nodeScale.py and hwcomponents' techscaling.py),",
        "#          area factors between nodes (45 nm row); stated accuracy R^2 > 0.95, area factors",
        "#          to two significant figures. Rows: energy LP45 -> "
        + ("LP32" if node == "32" else "HP" + node if node != "22" else "LP32/HP20")
        + ", delay HP45 -> "
        + ("HP" + node if node != "22" else "HP32/HP20")
        + ".",
        f"#  [CELL] published 6T SRAM bit cells: {cell_source}: {cell} um2;",
        f"#          {cell45_source}: {cell45} um2.",
    ]
    if interpolated:
        head += [
            "#  22 nm is not a node of [SB17] (its nodes: 180, 130, 90, 65, 45, 32, 20, 16, 14, 10, 7):",
            "#  its delay, energy and area factors are interpolated 10/12 of the way from 32 to 20 nm,",
            "#  linearly in the node (as hwcomponents interpolates), each fit at 0.9 V, the nominal",
            "#  supply of both neighbours (PTM 32 nm, PTM-MG 20 nm).",
        ]
    head += [
        "#  Factors used below:",
        f"#    energy x {ef} = E({node} nm, {NODES[node]['vdd']} V) / E(45 nm, 0.9 V) = "
        f"{sig(fit(ENERGY, node))} / {sig(fit(ENERGY, '45'))}   [SB17] {fit_text('energy', node)}",
        f"#    logic area x {af}   [SB17] area table, 45 nm -> {node} nm"
        + (" (interpolated: 0.46 + 10/12 x (0.21 - 0.46))" if interpolated else ""),
        f"#    SRAM and cache area x {sf} = {cell} / {cell45}   [CELL] (bit cell over bit cell; the",
        "#      macro's periphery is taken to shrink as its cells)",
        f"#    leakage power x {ef}: leakage scales as energy (hwcomponents' tech_node_leak);",
        f"#      logic leakage per mm2 x {lf} = {ef} / {af}",
        f"#    gate delay {sig(delay_vs_90(node))} x the 90 nm node's = {sig(fit(DELAY, node))} / "
        f"{sig(fit(DELAY, '90'))}   [SB17] {fit_text('delay', node)} over the 90 nm fit at 1.2 V",
        "#  Size exponents and port factors: the 45 nm table's ([FIT], [CACTI] at 45 nm): the same",
        "#  macro organisation assumed. DRAM: off the accelerator's die and node, unchanged.",
        "version: 1",
        f"name: {node}nm",
        f"node_nm: {node}",
        f"vdd_v: {NODES[node]['vdd']}          # nominal supply ([SB17] fits evaluated at it)",
        f"gate_delay_vs_90nm: {sig(delay_vs_90(node))}   # [SB17] delay fit, above",
        "",
    ]
    lines = list(head)

    def group(name, items):
        lines.append(f"{name}:")
        for key, value, comment in items:
            lines.append(f"  {key + ':':<22}{value:<12} # {comment}")
        lines.append("")

    sr, ca, lo = base["sram"], base["cache"], base["logic"]
    by = {"cell": (s, sf, "[CELL]"), "energy": (e, ef, "[SB17]")}

    def rows(g, scaled):
        """Every key of group g: those in `scaled` times their factor, the rest kept."""
        out = []
        for key, value in g.items():
            if key in scaled:
                f, text, source = by[scaled[key]]
                out.append((key, sig(value * f), f"{value} x {text} {source}"))
            else:
                out.append((key, sig(value), "45 nm table"))
        return out

    group("sram", rows(sr, {"area_mm2": "cell", "read_pj": "energy", "write_pj": "energy",
                            "leakage_mw": "energy"}))
    group("cache", rows(ca, {"area_mm2": "cell", "lookup_pj": "energy", "fill_pj": "energy",
                             "leakage_mw": "energy"}))
    logic = []
    for key in ["fp32_add", "fp32_mul", "int32_add", "int32_mul", "compare32", "register32"]:
        logic.append((key + "_pj", sig(lo[key + "_pj"] * e), f"{lo[key + '_pj']} x {ef} [SB17]"))
        logic.append((key + "_um2", sig(lo[key + "_um2"] * a), f"{lo[key + '_um2']} x {af} [SB17]"))
    logic.append(
        (
            "leakage_mw_per_mm2",
            sig(lo["leakage_mw_per_mm2"] * leak_logic),
            f"{lo['leakage_mw_per_mm2']} x {ef} / {af} [SB17]",
        )
    )
    group("logic", logic)
    lines.append(f"dram_pj_per_bit: {sig(base['dram_pj_per_bit'])}          # 45 nm table: [H14], off chip")
    lines.append(f"idle_leakage_fraction: {sig(base['idle_leakage_fraction'])}   # no power gating")
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 if a shipped table differs")
    parser.add_argument("--factors", action="store_true", help="print the factors per node")
    args = parser.parse_args()
    if args.factors:
        print(f"gate delay 130 nm (1.3 V) / 90 nm (1.2 V): {sig(delay_130_vs_90())}")
        for node in NODES:
            print(
                f"{node:>3} nm  {NODES[node]['vdd']} V  delay/90nm {sig(delay_vs_90(node))}  "
                f"energy/45nm {sig(energy_vs_45(node))}  area/45nm "
                f"{sig(area_vs_45(node)) if node != '45' else 1}"
            )
        return 0
    base = yaml.safe_load((HERE / "45nm.tech.yaml").read_text())
    stale = []
    for node in TARGETS:
        path = HERE / f"{node}nm.tech.yaml"
        text = table_text(node, base)
        if args.check:
            if not path.exists() or path.read_text() != text:
                stale.append(path.name)
        else:
            path.write_text(text)
    if stale:
        print("stale (re-run hw_model/tech/scale_tech.py): " + ", ".join(stale), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
