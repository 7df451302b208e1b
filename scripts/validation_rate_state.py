"""The rate-and-state slider beside the experiments: the sections of docs/VALIDATION.md that
scripts/validation_report.py writes from the sweeps sweeps/rate_state_*.yaml and
sweeps/slip_weakening_normal_load.yaml (issue 38)."""
import csv
import math
import os

import matplotlib.pyplot as plt
import numpy
import yaml

import sweep
import validation_report as vr  # its helpers, used once both modules are loaded
from sweep import extended_precursors, first_global, precursors

SWEEPS = ["rate_state_normal_load", "rate_state_resolution", "slip_weakening_normal_load", "rate_state_slide_hold_slide"]
with open(os.path.join(sweep.ROOT, "friction_sim/scenes/pmma_2d_rate_state.yaml")) as _scene:
    _SCENE = yaml.safe_load(_scene)
_LAW = {key: float(value) for key, value in _SCENE["friction"].items() if key != "law"}
DEFAULT_LOAD = float(_SCENE["load"]["normal_force"])  # N
DEFAULT_RUN = "normal_force=%g" % DEFAULT_LOAD  # its run in sweeps/rate_state_normal_load.yaml
SLIDER_LENGTH = float(_SCENE["geometry"]["length"])  # m


def spacing(nodes_x):
    """m, the lattice spacing along the slider with `nodes_x` nodes in a row."""
    return SLIDER_LENGTH / (nodes_x - 1)


DEFAULT_SPACING = spacing(int(_SCENE["lattice"]["nodes_x"]))  # m, the scene's own lattice


def nucleation_length(normal_force):
    """m, L_b = G·D/(b·f0·σ̄) with G = 3E/8 (ν = 1/3) and σ̄ = F_Z/(L·B)."""
    geometry = _SCENE["geometry"]
    sigma = normal_force / (float(geometry["length"]) * float(geometry["width"]))
    shear_modulus = 3 * vr.E / 8
    return shear_modulus * _LAW["characteristic_slip"] / (_LAW["ageing_effect"] * _LAW["reference_coefficient"] * sigma)


def event_nodes(sweep_name, run, columns=("front_speed_m_s", "peak_slip_velocity_m_s")):
    """event index → [(x (m), then each of `columns`)] of a run's event_nodes.csv, for the nodes whose first
    column is finite (by default: the nodes with a front speed, with their peak slip velocity)."""
    out = {}
    with open(os.path.join(sweep.ROOT, "sweeps", sweep_name, "runs", run, "event_nodes.csv")) as handle:
        for r in csv.DictReader(handle):
            values = [float(r[column]) for column in columns]
            if math.isfinite(values[0]):
                out.setdefault(r["event"], []).append(tuple([float(r["x_m"])] + values))
    return out


def slow_speed():
    """m/s, c_R/10: below it a front is slow (Rubinstein, Cohen & Fineberg 2004)."""
    return vr.C_R / 10


def front_type(speed):
    if not math.isfinite(speed):
        return "no running front"
    if speed < slow_speed():
        return "slow (< c_R/10)"
    if speed < vr.C_R:
        return "sub-Rayleigh"
    if speed < vr.C_S:
        return "c_R – c_S"
    return "intersonic (> c_S)"


def fast_to_slow(points, fit_nodes, run_length=3):
    """(x where it turns slow, m of slow running after it) for a front that ran fast (c_R/10 to c_L) for
    `run_length` nodes and then slow for at least as many, or None. The fits within `fit_nodes` of where
    the event began are left out: they mix the nucleation patch's near-simultaneous unsticking in."""
    points = sorted(points)
    if len(points) < 2:
        return None
    gap = min(b[0] - a[0] for a, b in zip(points, points[1:]))
    points = [p for p in points if p[0] >= points[0][0] + fit_nodes * gap]
    speeds = [p[1] for p in points]
    slow = slow_speed()
    for i in range(run_length, len(speeds) - run_length + 1):
        if all(slow <= s < vr.C_L for s in speeds[i - run_length:i]) and all(s < slow for s in speeds[i:i + run_length]):
            end = next((j for j in range(i, len(speeds)) if speeds[j] >= slow), len(speeds))
            return points[i][0], points[end - 1][0] - points[i][0]
    return None


def onset_prestress(sweep_name, run):
    """{event index: [(x (m), τ/σ, τ/(µ_s·σ))]} at the interface at each event's onset, from a run's
    stresses.csv: the stress ratio, and how near each node is to failing under its own static friction."""
    out = {}
    with open(os.path.join(sweep.ROOT, "sweeps", sweep_name, "runs", run, "stresses.csv")) as handle:
        for row in csv.DictReader(handle):
            normal = float(row["interface_normal_stress_Pa"])
            if row["phase"] == "onset" and normal > 0:
                ratio = float(row["interface_shear_stress_Pa"]) / normal
                out.setdefault(row["event"], []).append(
                    (float(row["x_m"]), ratio, ratio / float(row["interface_static_coefficient"])))
    return out


def mean_ratio(profile, low, high, column=1):
    """The mean of `column` of `profile` (onset_prestress) over low <= x < high (m), or nan."""
    values = [point[column] for point in profile if low <= point[0] < high]
    return sum(values) / len(values) if values else float("nan")


def still_slipping_behind(times, turn_x, slow_end_x):
    """(slipping, all): of the nodes behind `turn_x` (m) that slipped, those still slipping when the front
    has run slow to `slow_end_x` (m), the moment its last slow node unstuck."""
    reached = max((first for x, first, _ in times if x <= slow_end_x), default=math.nan)
    behind = [last for x, _, last in times if x < turn_x]
    return sum(1 for last in behind if last >= reached), len(behind)


def slides_after_holds(protocol_path):
    """[(the hold before a slide (s), the slide's start and end (s))] of a slide-hold-slide protocol."""
    with open(os.path.join(sweep.ROOT, protocol_path)) as handle:
        steps = yaml.safe_load(handle)["steps"]
    windows, start, hold = [], 0.0, None
    for step in steps:
        duration = float(step["duration"])
        if step["action"] == "drive" and hold is not None:
            windows.append((hold, start, start + duration))
        hold = duration if step["action"] == "hold" else None
        start += duration
    return windows


def slide_peaks(run_dir, windows):
    """[(the hold before a slide (s), the peak F_X/F_Z during that slide)] of a run that followed a
    slide-hold-slide protocol (`windows`: slides_after_holds), from its loading.csv."""
    peaks = [-math.inf] * len(windows)
    with open(os.path.join(run_dir, "loading.csv")) as handle:
        for row in csv.DictReader(handle):
            time = float(row["time_s"])
            for i, (_, begin, end) in enumerate(windows):
                if begin <= time <= end:
                    peaks[i] = max(peaks[i], float(row["shear_force_N"]) / float(row["normal_force_N"]))
    return [(w[0], peak) for w, peak in zip(windows, peaks)]


def ages_at_peaks(run_dir, windows, trailing_length):
    """Per slide (`windows`: slides_after_holds), at the onset of its event with the highest F_X/F_Z, over
    the contacts (normal stress > 0), from the run's stresses.csv: the median static coefficient µ(0, φ)
    within `trailing_length` (m) of the trailing edge, the same for the other contacts, and the load's
    concentration there, the median τ/σ within `trailing_length` over the event's F_X/F_Z; nans for a
    slide without an event."""
    strongest = {}
    with open(os.path.join(run_dir, "events.csv")) as handle:
        for row in csv.DictReader(handle):
            onset, ratio = float(row["onset_time_s"]), float(row["shear_ratio"])
            for i, (_, begin, end) in enumerate(windows):
                if begin <= onset <= end and ratio > strongest.get(i, (None, -math.inf))[1]:
                    strongest[i] = (row["index"], ratio)
    wanted = {event: i for i, (event, _) in strongest.items()}
    # Per slide: [µ(0, φ) within trailing_length, µ(0, φ) beyond it, τ/σ within it over F_X/F_Z].
    values = {i: ([], [], []) for i in range(len(windows))}
    with open(os.path.join(run_dir, "stresses.csv")) as handle:
        for row in csv.DictReader(handle):
            normal = float(row["interface_normal_stress_Pa"])
            if row["phase"] != "onset" or row["event"] not in wanted or not normal > 0:
                continue
            slide = wanted[row["event"]]
            trailing = float(row["x_m"]) < trailing_length
            values[slide][0 if trailing else 1].append(float(row["interface_static_coefficient"]))
            if trailing:
                values[slide][2].append(float(row["interface_shear_stress_Pa"]) / normal / strongest[slide][1])
    return [tuple(float(numpy.median(v)) if v else math.nan for v in values[i]) for i in range(len(windows))]


def reach_envelope(events):
    """[(onset F_X/F_Z, the largest L_p/L reached by then)] over a run's precursors, in their order: the
    interface's invaded extent as the load rises, whatever the lattice splits it into."""
    envelope, reach = [], 0.0
    for event in precursors(events):
        reach = max(reach, vr.f(event, "length_ratio"))
        envelope.append((vr.f(event, "shear_ratio"), reach))
    return envelope


def reach_at(envelope, load):
    """The largest L_p/L reached by precursors with onsets at or below `load` (F_X/F_Z)."""
    return max([reach for onset, reach in envelope if onset <= load] + [0.0])


def log_slope(points):
    """The least-squares slope of y against ln x over the finite points (x, y); nan with fewer than two."""
    finite = [(x, y) for x, y in points if math.isfinite(y)]
    if len(finite) < 2:
        return math.nan
    return numpy.polyfit(numpy.log([x for x, _ in finite]), [y for _, y in finite], 1)[0]


def law_peak(hold, speed):
    """The single block's peak after a hold (s) from steady sliding at `speed` (m/s): µ(0, D/V + hold)."""
    age = _LAW["characteristic_slip"] / speed + hold
    return _LAW["reference_coefficient"] * (1 + _LAW["ageing_effect"] * math.log1p(age / _LAW["reference_age"]))


def extended(events):
    """A run's precursors with an extent and its first global event: what the figures draw (the
    single-node slips and back-slips of a creeping interface would hide the curve)."""
    g = first_global(events)
    return extended_precursors(events) + ([g] if g else [])


def sections(data):
    """The report's lines for the rate-and-state items, from the runs of SWEEPS in `data`."""
    loads = data["rate_state_normal_load"]
    default = loads[DEFAULT_RUN]
    nodes = event_nodes("rate_state_normal_load", DEFAULT_RUN)
    g = first_global(default)
    pre = precursors(default)
    L = ["## 10. The rate-and-state slider (issue 38)", "",
         "`pmma_2d_rate_state`: the default slider with `friction.law: rate_state` (MODEL.md §4, PMMA values of "
         "Bar-Sinai et al. 2014), contacts 100 s old when the stage starts, events counted from a slip speed of "
         "1 mm/s (docs/analysis.md, slip events). 57 × 31, to the first global event. Nucleation length "
         "L_b = G·D/(b·f0·σ̄) = %.1f mm at F_Z = %g N: %.1f lattice spacings." % (
             nucleation_length(DEFAULT_LOAD) * 1e3, DEFAULT_LOAD,
             nucleation_length(DEFAULT_LOAD) / DEFAULT_SPACING), "",
         "*Rig*: %d precursors before the first global event at F_X/F_Z = %.4f (µ_s,macro; Amontons–Coulomb "
         "with µ_s = 0.4: 6 precursors, 0.2078)." % (len(pre), vr.f(g, "peak_shear_ratio")) if g else "no global event", ""]

    # Front types, event by event.
    with_front = [e for e in default if vr.f(e, "rupture_length_m") > 0]
    L += ["### 10.1 Slow fronts", "",
          "*Experiment*: Rubinstein, Cohen & Fineberg (2004) see three front types: slow (about 5 % of c_S, more "
          "than ten times below c_R), sub-Rayleigh and intersonic.", "",
          "| event | F_X/F_Z | L_p/L | median v_c (m/s) | type | peak slip velocity (m/s, median over the front) |",
          "|---|---|---|---|---|---|"]
    counts = {}
    for e in with_front:
        speed = vr.f(e, "median_front_speed_m_s")
        kind = front_type(speed)
        counts[kind] = counts.get(kind, 0) + 1
        slips = [p[2] for p in nodes.get(e["index"], [])]
        L.append("| %s%s | %.4f | %.3f | %s | %s | %s |" % (
            e["index"], " (global)" if e["global"] == "1" else "", vr.f(e, "shear_ratio"), vr.f(e, "length_ratio"),
            vr.speed_cell(speed) if math.isfinite(speed) else "-", kind,
            "%.2g" % numpy.median(slips) if slips else "-"))
    fig, ax = plt.subplots(figsize=(5.6, 3.6))
    for e in with_front:
        points = sorted(nodes.get(e["index"], []))
        if len(points) >= 3:
            ax.plot([p[0] * 1e3 for p in points], [p[1] for p in points], marker=".",
                    label="global" if e["global"] == "1" else "event %s" % e["index"])
    ax.axhline(slow_speed(), color="gray", linestyle=":")
    vr.save_speed_figure(fig, ax, "x (mm)", "validation_rate_state_fronts.png")
    L += ["", "![v_c(x) of the rate-and-state slider](figures/validation_rate_state_fronts.png)", "",
          "*Rig*: %s (c_R/10 = %.0f m/s, dotted). *Agreement*: %s" % (
              ", ".join("%d %s" % (n, kind) for kind, n in sorted(counts.items())), slow_speed(),
              "yes — slow fronts appear with the rate-and-state law, which Amontons–Coulomb never gave."
              if counts.get("slow (< c_R/10)") else
              "no slow fronts with the default parameters; the range where they appear is not yet searched."), ""]

    # Fast to slow within one event.
    fit_nodes = int(_SCENE["instruments"]["front_fit_nodes"])
    transitions = [(e["index"], t) for e in with_front for t in [fast_to_slow(nodes.get(e["index"], []), fit_nodes)] if t]
    # The prestress τ/σ at the event's onset, and τ/(µ_s·σ), where the front ran fast (the three nodes before
    # it turned) and where it ran slow; and whether the slip behind still ran while the front ran slow.
    prestress = onset_prestress("rate_state_normal_load", DEFAULT_RUN)
    times = event_nodes("rate_state_normal_load", DEFAULT_RUN, ("first_unstick_time_s", "last_slip_time_s"))
    rows = []
    for i, (turn, run_slow) in transitions:
        profile = prestress.get(i, [])
        fast, slow = (turn - 3 * DEFAULT_SPACING, turn), (turn, turn + run_slow + 0.5 * DEFAULT_SPACING)
        rows.append((i, turn, run_slow, mean_ratio(profile, *fast), mean_ratio(profile, *slow),
                     mean_ratio(profile, *fast, column=2), mean_ratio(profile, *slow, column=2),
                     still_slipping_behind(times.get(i, []), turn, turn + run_slow)))
    lower = sum(1 for row in rows if row[4] < row[3])
    nearer = sum(1 for row in rows if row[6] < row[5])
    carried = sum(1 for row in rows if row[7][1] > 0 and row[7][0] == row[7][1])
    L += ["### 10.2 The fast-to-slow transition within one event", "",
          "*Experiment* (Trømborg et al., PNAS 2014): a fast front turns slow as it enters a region of low "
          "prestress, carried by the slow slip left behind.", "",
          "*Rig*: events whose front runs between c_R/10 and c_L for three nodes and then below c_R/10 for "
          "three or more, beyond the nucleation's %d nodes (v_c(x) in §10.1's figure). At the event's onset, "
          "where the front ran fast (its last three nodes) and where it ran slow: the prestress τ/σ, and "
          "τ/(µ_s·σ), the share of its own static friction µ(0, φ) each contact bears. *Behind*: of the nodes "
          "the front passed before it turned slow, those still slipping when it ended its slow run "
          "(`last_slip_time_s` of event_nodes.csv):" % fit_nodes, "",
          "| event | turns slow at x (mm) | runs slow for (mm) | τ/σ where fast | τ/σ where slow "
          "| τ/(µ_s·σ) where fast | τ/(µ_s·σ) where slow | behind, still slipping |",
          "|---|---|---|---|---|---|---|---|"]
    L += ["| %s | %.0f | %.0f | %.3f | %.3f | %.3f | %.3f | %d of %d |" % (
        i, turn * 1e3, run_slow * 1e3, fast, slow, fast_share, slow_share, behind[0], behind[1])
        for i, turn, run_slow, fast, slow, fast_share, slow_share, behind in rows]
    L += ["", "*Agreement*: %s" % (
        "a fast front turning slow is shown in %d of %d events with a front. The front slows where τ/σ is "
        "lower in %d of them, and where τ/(µ_s·σ) is lower — where the contacts are further from failing "
        "under their own, age-dependent, static friction — in %d: %s In %d of %d the whole region behind "
        "the turn still slips while the front runs slow: %s" % (
            len(transitions), len(with_front), lower, nearer,
            "with ageing the measure that matters is τ/(µ_s·σ), and by it the rig agrees with Trømborg et al."
            if nearer == len(rows) else
            "by it the rig agrees with Trømborg et al. in most events." if 2 * nearer > len(rows) else
            "the rig does not show the low-prestress mechanism.",
            carried, len(rows),
            "the slow front runs with the slow slip behind it, as Trømborg et al. describe%s." % (
                "" if carried == len(rows) else
                "; in the other %d the slip behind had stopped, and the front ran slow on its own" % (len(rows) - carried))
            if 2 * carried > len(rows) else
            "in the others the slip behind has stopped, so the slow front runs on its own.")
        if transitions else "not shown at this resolution."), ""]

    # Slip velocity against front speed.
    pairs = [(p[1], p[2]) for v in nodes.values() for p in v if 0 < p[1] < vr.C_L and p[2] > 0]
    L += ["### 10.3 Slip velocity against front speed", "",
          "*Experiment* (Ben-David, Cohen & Fineberg 2010) and the Oslo model: the slip velocity behind a front "
          "is proportional to the front speed over the whole range.", ""]
    if len(pairs) > 2:
        lv = numpy.log([p[0] for p in pairs])
        ls = numpy.log([p[1] for p in pairs])
        slope, intercept = numpy.polyfit(lv, ls, 1)
        ratio = numpy.exp(numpy.median(ls - lv))
        scatter = float(numpy.std(ls - (slope * lv + intercept)))
        fig, ax = plt.subplots(figsize=(5.6, 3.6))
        ax.loglog([p[0] for p in pairs], [p[1] for p in pairs], ".", markersize=3)
        ax.set_xlabel("front speed v_c (m/s)")
        ax.set_ylabel("peak slip velocity (m/s)")
        fig.tight_layout()
        fig.savefig(os.path.join(vr.FIG, "validation_rate_state_slip_velocity.png"), dpi=100)
        plt.close(fig)
        L += ["![slip velocity against front speed](figures/validation_rate_state_slip_velocity.png)", "",
              "*Rig*: %d node crossings (every event of the default run, fits below c_L): log–log slope %.2f "
              "(1 is proportional), peak slip velocity / v_c = %.1e at the median, scatter %.2f in ln about the "
              "fit. *Agreement*: %s" % (
                  len(pairs), slope, ratio, scatter,
                  "yes, proportional within the scatter." if abs(slope - 1) < 0.2 else
                  "the two grow together, but not in proportion (slope %.2f)." % slope), ""]
    else:
        L += ["*Rig*: too few node crossings to fit.", ""]

    # Ageing of the slider.
    with open(os.path.join(sweep.ROOT, "sweeps/rate_state_slide_hold_slide.yaml")) as handle:
        protocol = yaml.safe_load(handle)["protocol"]
    windows = slides_after_holds(protocol)
    run_dir = os.path.join(sweep.ROOT, "sweeps/rate_state_slide_hold_slide/runs/base")
    peaks = slide_peaks(run_dir, windows)
    trailing = nucleation_length(DEFAULT_LOAD)
    ages = ages_at_peaks(run_dir, windows, trailing)
    speed = float(_SCENE["stage"]["program"][0]["speed"])
    slope = log_slope([(hold, peak) for hold, peak in peaks])
    block_slope = _LAW["ageing_effect"] * _LAW["reference_coefficient"]
    age_slopes = [log_slope([(hold, age[side]) for (hold, _), age in zip(peaks, ages)]) for side in (0, 1)]
    # Where the load concentrates the slider gives way once τ there reaches µ(0, φ)·σ there: at a peak
    # F_X/F_Z of about µ(0, φ) over the concentration.
    failing_slope = log_slope([(hold, young / concentration)
                               for (hold, _), (young, _, concentration) in zip(peaks, ages)])
    concentration_range = [a[2] for a in ages if math.isfinite(a[2])]
    L += ["### 10.4 Ageing of the slider (slide–hold–slide in 2D)", "",
          "*Experiment*: static friction grows as the logarithm of the hold time (Dieterich; Berthoud et al. "
          "1999 for PMMA).", "",
          "*Rig*: `%s` on `pmma_2d_rate_state`: slides at %.1f mm/s between holds of %g–%g s. Peak F_X/F_Z of "
          "each slide after a hold, beside the single block's µ(0, D/V + t_h) (tested to 10⁻³ in "
          "test_rate_state):" % (protocol, speed * 1e3, peaks[0][0], peaks[-1][0]), "",
          "| hold (s) | slider: peak F_X/F_Z | single block: µ(0, D/V + t_h) | µ(0, φ) within L_b of the trailing "
          "edge | µ(0, φ) of the rest | τ/σ within L_b over F_X/F_Z |", "|---|---|---|---|---|---|"]
    L += ["| %g | %.4f | %.4f | %.4f | %.4f | %.3f |" % (hold, peak, law_peak(hold, speed), young, rest, concentration)
          for (hold, peak), (young, rest, concentration) in zip(peaks, ages)]
    rising = all(b[1] > a[1] for a, b in zip(peaks, peaks[1:]))
    if slope > 0 and rising:
        verdict = "yes: the slider's static friction grows with the logarithm of the hold."
    elif slope > 0:
        verdict = ("weakly: the fit's slope is positive, but the peaks do not rise with every longer hold, and the "
                   "slope is %.0f times below the block's." % (block_slope / slope))
    else:
        verdict = "no: the slider's peak does not grow with the hold."
    if all(math.isfinite(a) for a in age_slopes):
        reading = ("Node by node (stresses.csv, the contacts touching the track at the onset of each slide's strongest "
                   "event; L_b = %.1f mm): the median µ(0, φ) within L_b of the trailing edge rises by %.4f per "
                   "e-fold of the hold, the rest's by %.4f, %.2f and %.2f times the block's b·f0, and the slider's "
                   "peak by %.2f times it." % (trailing * 1e3, age_slopes[0], age_slopes[1],
                                               age_slopes[0] / block_slope, age_slopes[1] / block_slope,
                                               slope / block_slope))
        if math.isfinite(failing_slope) and concentration_range:
            reading += (" The load concentrates at the trailing edge: τ/σ there is %.2f–%.2f times F_X/F_Z and "
                        "changes by %+.3f per e-fold of the hold, so that the peak expected where the contacts there "
                        "fail, µ(0, φ) over that concentration, rises by %.4f per e-fold, %.2f times the slider's "
                        "%.4f. %s" % (
                            min(concentration_range), max(concentration_range),
                            log_slope([(hold, a[2]) for (hold, _), a in zip(peaks, ages)]), failing_slope,
                            failing_slope / slope if slope else math.nan, slope,
                            "The concentration growing with the hold is what keeps the slider's peak from ageing "
                            "as its contacts do." if abs(failing_slope - slope) < 0.5 * (age_slopes[0] - slope) else
                            "The concentration does not account for the difference either; why the peak ages less "
                            "than its contacts is not shown here."))
    else:
        reading = "Too few slides with an event to follow the contacts' age node by node."
    L += ["", "Slope against ln t_h (least squares): %.4f for the slider, %.4f (b·f0) for the block. *Agreement*: "
          "%s %s" % (slope, block_slope, verdict, reading), ""]

    # Load dependence, with slip weakening beside it.
    fig_loads = vr.figure("validation_rate_state_loads.png", [
        ("rate_state, F_Z (N)", [(k.split("=")[1], extended(v)) for k, v in vr.by_value(loads)]),
        ("slip weakening ξ_µ = 3 µm, F_Z (N)",
         [(k.split("=")[1], extended(v)) for k, v in vr.by_value(data["slip_weakening_normal_load"])])])
    L += ["### 10.5 Load dependence", "",
          "*Experiment* (Katano et al., Sci. Rep. 2014): the L_p/L–F_X/F_Z curves depend on F_Z, and "
          "µ_s,macro falls as F_Z rises.", "", "![precursors at four loads](%s)" % fig_loads, "",
          "The figures draw the precursors with L_p > 0 and the first global event (star).", "",
          "| F_Z (N) | L_b (mm) | rate_state precursors | rate_state µ_s,macro | slip weakening precursors | "
          "slip weakening µ_s,macro |", "|---|---|---|---|---|---|"]
    weakening = dict(data["slip_weakening_normal_load"])
    macros = []
    for k, v in vr.by_value(loads):
        other = weakening.get(k, [])
        gg = first_global(v)
        macros.append((float(k.split("=")[1]), vr.f(gg, "peak_shear_ratio") if gg else math.nan))
        L.append("| %s | %.1f | %d | %s | %d | %s |" % (
            k.split("=")[1], nucleation_length(float(k.split("=")[1])) * 1e3, len(precursors(v)), vr.macro_cell(v),
            len(precursors(other)), vr.macro_cell(other)))
    falling = all(b[1] < a[1] for a, b in zip(macros, macros[1:]))
    L += ["", "*Agreement*: %s Both laws have a length (D, ξ_µ), so neither collapses exactly with F_Z as "
          "Amontons–Coulomb does (§2)." % (
              "yes for µ_s,macro: it falls monotonically as F_Z rises." if falling else
              "µ_s,macro does not fall monotonically with F_Z (%s)." % ", ".join(
                  "%.4f at %g N" % (m, fz) for fz, m in macros)), ""]

    # Convergence with the lattice.
    res = data["rate_state_resolution"]
    by_size = sorted(res.items(), key=lambda item: int(item[0].split("nodes_x=")[1].split("_")[0]))
    length = nucleation_length(DEFAULT_LOAD)
    coulomb = sorted(data["resolution"].items(), key=lambda item: int(item[0].split("nodes_x=")[1].split("_")[0]))
    coulomb_counts = [len(precursors(v)) for _, v in coulomb]
    L += ["### 10.6 Convergence with the lattice", "",
          "Amontons–Coulomb gives %s precursors at %s (§9): it has no length to converge to. The rate-and-state "
          "law has L_b (%.1f mm). Its trailing patch creeps and slips again and again over a slowly growing "
          "extent, and a finer lattice splits that creep into more, smaller events: counts of precursors cannot "
          "converge. What is compared is the invaded extent: the largest L_p/L reached by the precursors as "
          "F_X/F_Z rises (the curves of the figure), and µ_s,macro." % (
              ", ".join(map(str, coulomb_counts)),
              ", ".join("%s × %s" % (k.split("nodes_x=")[1].split("_")[0], k.split("nodes_z=")[1].split("_")[0])
                        for k, _ in coulomb), length * 1e3),
          "", "| lattice | L_b / spacing | precursors | with L_p > 0 | longer than L_b | µ_s,macro | largest L_p/L "
          "reached at F_X/F_Z = 0.30, 0.33, 0.36 |", "|---|---|---|---|---|---|---|"]
    labels, spans, envelopes, macros = [], [], [], []
    for k, v in by_size:
        nx = int(k.split("nodes_x=")[1].split("_")[0])
        labels.append("%d × %s" % (nx, k.split("nodes_z=")[1].split("_")[0]))
        spans.append(length / spacing(nx))
        envelopes.append(reach_envelope(v))
        g = first_global(v)
        macros.append(vr.f(g, "peak_shear_ratio") if g else math.nan)
        L.append("| %s | %.1f | %d | %d | %d | %s | %s |" % (
            labels[-1], spans[-1], len(precursors(v)), len(extended_precursors(v)),
            sum(1 for e in precursors(v) if vr.f(e, "rupture_length_m") > length), vr.macro_cell(v),
            ", ".join("%.2f" % reach_at(envelopes[-1], ratio) for ratio in (0.30, 0.33, 0.36))))
    if len(by_size) < 2:
        return L + ["", "Fewer than two lattices finished: nothing to compare.", ""]
    fig_res = vr.figure("validation_rate_state_resolution.png", [
        ("rate_state, lattice", [(label, extended(v)) for label, (_, v) in zip(labels, by_size)])])
    L += ["", "![rate_state at each resolution](%s)" % fig_res, "",
          "For each refinement, coarse → fine: the relative difference of µ_s,macro, and the median difference "
          "of the largest L_p/L reached, over 50 loads from where both lattices' precursors first reach L_b to the "
          "lower µ_s,macro.", "", "| refinement | Δµ_s,macro | Δ(largest L_p/L), median |", "|---|---|---|"]
    macro_changes, reach_changes = [], []
    for i in range(1, len(by_size)):
        starts = [next((onset for onset, reach in envelope if reach * SLIDER_LENGTH > length),
                       math.nan) for envelope in envelopes[i - 1:i + 1]]
        low, high = max(starts), min(macros[i - 1], macros[i])
        grid = numpy.linspace(low, high, 50) if low < high else []
        reach_changes.append(numpy.median([abs(reach_at(envelopes[i], x) - reach_at(envelopes[i - 1], x))
                                           for x in grid]) if len(grid) else math.nan)
        macro_changes.append(abs(macros[i] / macros[i - 1] - 1))
        L.append("| %s → %s | %.1f %% | %.3f |" % (labels[i - 1], labels[i], 100 * macro_changes[-1],
                                                    reach_changes[-1]))
    finest = "%s → %s" % (labels[-2], labels[-1])
    trends = []
    if len(macro_changes) > 1 and all(math.isfinite(x) for x in macro_changes[-2:] + reach_changes[-2:]):
        for name, changes, unit in (("µ_s,macro", [100 * c for c in macro_changes], " %%"),
                                    ("the invaded extent", reach_changes, " L")):
            trends.append("%s's difference %s (%.3g%s → %.3g%s)" % (
                name, "narrows" if changes[-1] <= changes[-2] else "grows", changes[-2], unit, changes[-1], unit))
        trend = "From one refinement to the next, %s." % " and ".join(trends)
        if reach_changes[-1] <= reach_changes[-2]:
            trend += (" The invaded extent holds to %.3f L once L_b spans %.0f spacings (%s)." % (
                reach_changes[-1], spans[-2], labels[-2]))
        if macro_changes[-1] > macro_changes[-2]:
            trend += (" µ_s,macro is not converged at these resolutions: no lattice here gives it to better than "
                      "%.0f %%." % (100 * macro_changes[-1]))
    else:
        trend = "One refinement only: whether the differences narrow needs another."
    coulomb_rising = all(b > a for a, b in zip(coulomb_counts, coulomb_counts[1:]))
    L += ["", "*Agreement*: %s: µ_s,macro within %.1f %%, the invaded extent within %.3f L (median). %s "
          "Amontons–Coulomb's count %s (%s)." % (
              finest, 100 * macro_changes[-1], reach_changes[-1], trend.replace("%%", "%"),
              "rises at every refinement" if coulomb_rising else "changes with the lattice",
              " → ".join(map(str, coulomb_counts))), ""]

    # The kink.
    L += ["### 10.7 The kink", "", "Two lines against one line and against a parabola, as in §2, on the "
          "invading front of each run:", "",
          "| run | points | kink at F_X/F_Z | slopes below / above | ΔBIC over one line | ΔBIC over a parabola |",
          "|---|---|---|---|---|---|"]
    kinks = [(k, vr.fit_kink([(vr.f(e, "shear_ratio"), vr.f(e, "length_ratio")) for e in vr.front(v)]))
             for k, v in vr.by_value(loads)]
    for (k, kink), (_, v) in zip(kinks, vr.by_value(loads)):
        if kink is None:
            L.append("| F_Z = %s N | %d | fewer than 6 points | | | |" % (k.split("=")[1], len(vr.front(v))))
            continue
        L.append("| F_Z = %s N | %d | %.4f | %.1f / %.1f | %.1f | %.1f |" % (
            k.split("=")[1], kink["n"], kink["breakpoint"], kink["slopes"][0], kink["slopes"][1], kink["over_line"],
            kink["over_parabola"]))
    kinked = [(k.split("=")[1], kink["breakpoint"]) for k, kink in kinks
              if kink and kink["over_line"] > 6 and kink["over_parabola"] > 6]
    others = [k.split("=")[1] for k, kink in kinks if kink and (k.split("=")[1], kink["breakpoint"]) not in kinked]
    where = ", ".join("F_X/F_Z = %.3f for %s N" % (x, fz) for fz, x in kinked)
    if len(kinked) > 1:
        verdict = ("two linear regimes with a kink (ΔBIC > 6 over one line and over a parabola) at %s; it moves "
                   "with F_Z, as Katano et al. see." % where)
    elif kinked:
        verdict = ("two linear regimes with a kink (ΔBIC > 6 over one line and over a parabola) at %s only%s: "
                   "whether it moves with F_Z, as Katano et al. see, is not shown." % (
                       where, "; at %s N two lines do not beat a parabola by that margin" % " and ".join(others)
                       if others else ""))
    else:
        verdict = "no kink that two lines fit better than one line and a parabola."
    L += ["", "*Agreement*: %s The lighter loads give too few precursors to tell (their L_b is long)." % verdict, ""]
    return L
