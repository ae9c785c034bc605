#!/usr/bin/env python3
"""The report of `lmgi tradeoff` (docs/tradeoff.md): reads DIR/tradeoff.json and the error maps the command
wrote beside it, draws the plots with matplotlib and writes DIR/report.html, which opens in any browser
without a network (its pictures are the PNG files beside it).

usage: tradeoff_report.py DIR [-q]
"""
import html
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

# Knobs whose cost is paid every update rather than in the full solution (trace, AIMs, gather).
UPDATE_COST = {"texels_per_frame", "caustic_photons", "caustic_filter", "caustic_filter_photons", "tiled_k",
               "tiled_radius"}
# Knobs that change the frame but not the lightmaps: judged by the frame's error.
FRAME_ONLY = {"caustic_photons", "caustic_filter", "caustic_filter_photons", "tiled_k", "tiled_radius",
              "texels_per_frame"}
# Knobs of the caustic pass: judged by the caustic part's error (a small share of the frame's light).
CAUSTIC = {"caustic_photons", "caustic_filter", "caustic_filter_photons"}


def finite(v):
    return v is not None and isinstance(v, (int, float)) and math.isfinite(v)


def num(v):
    """A JSON number, NaN for null (a setting the library refused has no numbers)."""
    return float(v) if finite(v) else math.nan


def cost_of(row):
    return num(row["ms"]["update"] if row["knob"] in UPDATE_COST else row["ms"]["solution"])


def frame_error(row):
    """The frame's error per visible surface: the per-pixel RMSE keeps the reference's own noise (about its
    target error), the surfaces' means average it away."""
    return row.get("frame_surface_rms")


def caustic_error(row):
    """The frame's caustic part against the reference's (relative RMSE over the compared pixels); None
    where the scene has no caustics or the row predates it."""
    return row.get("caustic", {}).get("rmse")


def error_of(row):
    """The error a knob is judged by: the caustic part's for the caustic pass's knobs, the IIM's where the
    knob changes the lightmaps, else the frame's."""
    if row["knob"] in CAUSTIC and finite(caustic_error(row)):
        return caustic_error(row)
    if row["knob"] not in FRAME_ONLY and finite(row["iim"]["rmse"]):
        return row["iim"]["rmse"]
    return frame_error(row)


def pareto(points):
    """Indices of the points (cost, error) no other point beats in both (ties kept once)."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def log_axes(ax, xs, ys):
    xs = [x for x in xs if finite(x) and x > 0]
    ys = [y for y in ys if finite(y) and y > 0]
    if xs and max(xs) / min(xs) > 4:
        ax.set_xscale("log")
    if ys and max(ys) / min(ys) > 4:
        ax.set_yscale("log")


def style(ax, xlabel, ylabel, legend_size=7):
    ax.set_xlabel(xlabel, fontsize=8)
    ax.set_ylabel(ylabel, fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, which="both", alpha=0.3)
    if legend_size:
        ax.legend(fontsize=legend_size)


def save(fig, scene, kind, title, out_dir, top=0.97):
    """Titles, lays out and writes the figure as DIR/plot_SCENE_KIND.png; returns the file's name."""
    fig.suptitle(f"{scene['name']}: {title}", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, top))
    name = f"plot_{scene['name']}_{kind}.png"
    fig.savefig(os.path.join(out_dir, name), dpi=90)
    plt.close(fig)
    return name


def knob_plots(scene, out_dir):
    """One panel per knob: its error against its cost, each point labelled with its value, the default
    starred."""
    knobs = []
    for r in scene["rows"]:
        if r["knob"] != "grid" and r["knob"] not in knobs:
            knobs.append(r["knob"])
    if not knobs:
        return None
    cols = 3
    rows_n = (len(knobs) + cols - 1) // cols
    fig, axes = plt.subplots(rows_n, cols, figsize=(4.6 * cols, 3.5 * rows_n), squeeze=False)
    for k, knob in enumerate(knobs):
        ax = axes[k // cols][k % cols]
        rs = sorted((r for r in scene["rows"] if r["knob"] == knob), key=lambda r: r["x"] if finite(r["x"]) else 0)
        # a grid's rows ("0.25 texels x N 32") are one line per value of its first knob
        series = {}
        for r in rs:
            series.setdefault(r["value"].split(" x ")[0] + " " if knob.startswith("grid_") else "", []).append(r)
        for name, part in series.items():
            xs = [cost_of(r) for r in part]
            metrics = (("iim", "o-", "IIM per texel", lambda r: r["iim"]["rmse"]),
                       ("frame", "s--", "frame per surface", frame_error),
                       ("caustic", "^:", "caustic part per pixel", caustic_error))
            for metric, line, what, value in metrics:
                if metric == "caustic" and knob not in CAUSTIC:
                    continue
                ys = [num(value(r)) for r in part]
                if not any(finite(y) for y in ys):
                    continue
                ax.plot(xs, ys, line, markersize=4, label=name + what)
                for r, x, y in zip(part, xs, ys):
                    if finite(y):
                        ax.annotate(r["value"], (x, y), textcoords="offset points", xytext=(3, 3), fontsize=7)
                        if r["default"]:
                            ax.plot([x], [y], "*", color="black", markersize=11, zorder=5)
        log_axes(ax, [cost_of(r) for r in rs], [frame_error(r) for r in rs] + [r["iim"]["rmse"] for r in rs] +
                 ([caustic_error(r) for r in rs] if knob in CAUSTIC else []))
        ax.set_title(rs[0]["label"], fontsize=9)
        style(ax, "ms per update" if knob in UPDATE_COST else "ms for the full solution", "relative error (RMS)")
    for k in range(len(knobs), rows_n * cols):
        axes[k // cols][k % cols].axis("off")
    return save(fig, scene, "knobs", "error against time per knob (star: the default)", out_dir)


def front_plot(scene, out_dir):
    """Every lightmap setting's frame and IIM error against the full solution's time, the Pareto front
    drawn through the ones nothing beats, the default starred."""
    rs = [r for r in scene["rows"] if r["knob"] not in UPDATE_COST and finite(r["iim"]["rmse"])]
    if not rs:
        return None, []
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.6))
    fronts = {}
    for ax, metric in zip(axes, ("iim", "frame")):
        pts = [(r["ms"]["solution"], r["iim"]["rmse"] if metric == "iim" else frame_error(r)) for r in rs]
        ax.scatter([p[0] for p in pts], [p[1] for p in pts], s=14, color="tab:blue", alpha=0.7, label="settings")
        front = pareto(pts)
        fronts[metric] = front
        ax.plot([pts[i][0] for i in front], [pts[i][1] for i in front], "-o", color="tab:red", markersize=4,
                label="Pareto front")
        for i in front:
            ax.annotate(f"{rs[i]['knob']} {rs[i]['value']}", pts[i], textcoords="offset points", xytext=(3, 3),
                        fontsize=6)
        for r, p in zip(rs, pts):
            if r["default"]:
                ax.plot([p[0]], [p[1]], "*", color="black", markersize=13, zorder=5, label="default")
                break
        log_axes(ax, [p[0] for p in pts], [p[1] for p in pts])
        style(ax, "ms for the full solution (trace + AIMs + gather)",
              "IIM relative RMSE per texel" if metric == "iim" else "frame relative error per surface (RMS)", 8)
    name = save(fig, scene, "front", "every setting, error against time", out_dir)
    return name, [rs[i] for i in fronts["frame"]]


def map_plots(scene, out_dir):
    """The signed relative error (estimate / reference - 1) per texel and per pixel, for the default, the
    fastest and the most accurate setting."""
    maps = scene.get("maps", {})
    which = [w for w in ("default", "fastest", "most_accurate") if w in maps]
    if not which:
        return None
    fig, axes = plt.subplots(2, len(which), figsize=(4.4 * len(which), 8), squeeze=False)
    cmap = plt.get_cmap("coolwarm").copy()
    cmap.set_bad("#c8c8c8")
    for c, w in enumerate(which):
        row = scene["rows"][maps[w]["row"]]
        for r, kind in enumerate(("iim", "frame")):
            ax = axes[r][c]
            m = np.load(os.path.join(out_dir, maps[w][kind]))
            img = ax.imshow(m, cmap=cmap, vmin=-0.3, vmax=0.3, origin="lower" if kind == "iim" else "upper",
                            interpolation="nearest")
            ax.set_title(f"{w.replace('_', ' ')}: {row['knob']} {row['value']}\n"
                         f"{'IIM per texel' if kind == 'iim' else 'frame per pixel'}, RMSE {row[kind]['rmse']:.3f}",
                         fontsize=8)
            ax.set_xticks([])
            ax.set_yticks([])
            fig.colorbar(img, ax=ax, fraction=0.046, pad=0.04).ax.tick_params(labelsize=7)
    return save(fig, scene, "maps", "relative error (estimate / reference - 1; grey: not compared)", out_dir)


# Edits this many updates apart or closer are one gesture (a drag commits its node every update): they
# share a panel of the lag plot, measured from the first, instead of a panel each of one update.
GESTURE_GAP = 2


def edit_groups(edits, frames):
    """The edits as gestures: (first, last, start, end): edits first..last, updates start..end (the next
    gesture's first update, or the script's end), and a title naming them."""
    groups = []
    for e, edit in enumerate(edits):
        if groups and edit["frame"] - edits[groups[-1][1]]["frame"] <= GESTURE_GAP:
            groups[-1][1] = e
        else:
            groups.append([e, e])
    out = []
    for g, (first, last) in enumerate(groups):
        start = edits[first]["frame"]
        end = edits[groups[g + 1][0]]["frame"] if g + 1 < len(groups) else frames
        names = list(dict.fromkeys(edits[k]["edit"] for k in range(first, last + 1)))
        if first == last:
            title = f"{names[0]} (update {start})"
        else:
            title = f"{', '.join(names)} x{last - first + 1} (updates {start}-{edits[last]['frame']})"
        out.append((first, last, start, end, title))
    return out


def lag_plot(scene, out_dir):
    """After each edit, or each gesture of edits a few updates apart, the lightmap's distance from the
    converged one against the update time spent since, one curve per update budget; the panels' titles."""
    plays = [p for p in scene.get("plays", []) if p["frames"]]
    if not plays:
        return None, []
    groups = edit_groups(plays[0]["edits"], scene["script_frames"])
    fig, axes = plt.subplots(1, len(groups), figsize=(4.4 * len(groups), 3.8), squeeze=False)
    for g, (first, last, start, end, title) in enumerate(groups):
        ax = axes[0][g]
        for p in plays:
            ms, xs, ys, fs, marks = 0.0, [], [], [], []
            for k, (err, t, _whole, frame) in enumerate(p["frames"][start:end]):
                ms += t
                xs.append(ms)
                ys.append(max(err, 1e-4))
                fs.append(max(frame, 1e-4) if frame is not None else None)
                if p["default"] and k and any(p["edits"][e]["frame"] == start + k for e in range(first + 1, last + 1)):
                    marks.append(ms)
            ax.plot(xs, ys, "-" if p["default"] else "--", linewidth=2.2 if p["default"] else 1.2,
                    label="defaults" if p["default"] else f"{p['knob']} {p['value']}")
            if any(f is not None for f in fs):
                ax.plot([x for x, f in zip(xs, fs) if f is not None], [f for f in fs if f is not None], ":",
                        color="black", linewidth=1.6, label="defaults: frame vs path-traced reference")
            for m in marks:  # the gesture's later edits, at the defaults' time
                ax.axvline(m, color="tab:red", linewidth=0.5, alpha=0.5)
        ax.axhline(0.05, color="grey", linewidth=0.8)
        ax.axhline(0.02, color="grey", linewidth=0.8, linestyle=":")
        ax.set_yscale("log")
        ax.set_title(title, fontsize=9)
        style(ax, "update ms since the edit" if first == last else "update ms since the first edit (red: the others)",
              "worst surface from converged (frame: vs reference)", 7 if g == 0 else 0)
    name = save(fig, scene, "lag", "update lag after each edit (lines at 5% and 2%)", out_dir, 0.93)
    return name, [gr[4] for gr in groups]


def lag_html(scene, out_dir):
    plays = [p for p in scene.get("plays", []) if p["frames"]]
    if not plays:
        return ""
    parts = [f"<h3>Update lag ({html.escape(scene['script'])})</h3>"]
    png, panels = lag_plot(scene, out_dir)
    if png:
        parts.append(f'<img src="{png}" alt="update lag">')
        parts.append("<p>Panels, one an edit, or one a gesture of edits at most {} updates apart (a drag): {}.</p>"
                     .format(GESTURE_GAP, "; ".join(html.escape(t) for t in panels)))

    def cell(f, ms):
        return f"{f} ({ms:.0f} ms)" if f >= 0 else f"not in {ms:.0f} ms"
    parts.append("<p>The distance is the relative L1 distance of the IIM from the converged IIM of the edited scene "
                 "on the surface furthest from it (surfaces of 16 valid texels or more).</p>")
    parts.append("<table><tr><th>edit</th><th>budget</th><th>distance at the edit</th><th>within 5%: updates "
                 "(ms)</th><th>within 2%</th></tr>")
    for e in range(len(plays[0]["edits"])):
        for p in plays:
            ed = p["edits"][e]
            parts.append("<tr><td>{}</td><td>{}</td><td>{:.1f}%</td><td>{}</td><td>{}</td></tr>".format(
                html.escape(ed["edit"]), "defaults" if p["default"] else html.escape(f"{p['knob']} {p['value']}"),
                100 * ed["error"], cell(ed["frames_to_5"], ed["ms_to_5"]), cell(ed["frames_to_2"], ed["ms_to_2"])))
    parts.append("</table>")
    checked = [p for p in plays if any(ed.get("frame_error") is not None for ed in p["edits"])]
    if checked:
        parts.append("<p>The frame at the defaults against the path-traced reference of the edited scene "
                     "(--frame-lag: per-surface error, the pixel-weighted RMS over surfaces of 20 compared pixels "
                     "or more; the converged frame keeps the method's own error, the last column).</p>")
        parts.append("<table><tr><th>edit</th><th>frame error at the edit</th><th>within 5%: updates (ms)</th>"
                     "<th>within 2%</th><th>at the end of its span</th></tr>")
        for ed in checked[0]["edits"]:
            def frame_cell(f, ms):
                return cell(f, ms) if ms is not None else ""
            parts.append("<tr><td>{}</td><td>{:.1f}%</td><td>{}</td><td>{}</td><td>{:.1f}%</td></tr>".format(
                html.escape(ed["edit"]), 100 * (ed["frame_error"] or 0), frame_cell(ed["frame_to_5"], ed["frame_ms_to_5"]),
                frame_cell(ed["frame_to_2"], ed["frame_ms_to_2"]), 100 * (ed["frame_end"] or 0)))
        parts.append("</table>")
    return "\n".join(parts)


def suggestions(scene):
    """Per knob: the cheapest value whose error is within 1% of the best the sweep reached (docs/tradeoff.md,
    "Defaults from the front")."""
    out = []
    knobs = []
    for r in scene["rows"]:
        if r["knob"] != "grid" and r["knob"] not in knobs:
            knobs.append(r["knob"])
    for knob in knobs:
        rs = [r for r in scene["rows"] if r["knob"] == knob and finite(error_of(r))]
        if not rs:
            continue
        best = min(error_of(r) for r in rs)
        ok = [r for r in rs if error_of(r) <= best * 1.01]
        pick = min(ok, key=cost_of)
        default = next((r for r in rs if r["default"]), None)
        out.append((knob, rs[0]["label"], default, pick, best))
    return out


def fmt(v, digits=4):
    return f"{v:.{digits}f}" if finite(v) else ""


def scene_html(scene, out_dir):
    parts = [f"<h2>{html.escape(scene['name'])}</h2>",
             f"<p>{html.escape(scene['path'])}: {len(scene['rows'])} settings; texel reference "
             f"{scene['reference_texels_seconds']:.1f} s (relative standard error {scene['reference_texels_rel_se']:.3f})."
             "</p>"]
    front_png, front = front_plot(scene, out_dir)
    if front_png:
        parts.append(f'<img src="{front_png}" alt="error against time, every setting">')
        parts.append("<p>On the frame's front: " + ", ".join(
            html.escape(f"{r['knob']} {r['value']} ({r['ms']['solution']:.0f} ms, {frame_error(r):.4f})")
            for r in front) + ".</p>")
    knobs_png = knob_plots(scene, out_dir)
    if knobs_png:
        parts.append(f'<img src="{knobs_png}" alt="error against time per knob">')
    parts.append("<h3>Defaults against the front</h3><table><tr><th>knob</th><th>default</th><th>its error</th>"
                 "<th>cheapest within 1% of the best</th><th>its error</th><th>its cost (ms)</th><th>default's cost</th></tr>")
    for knob, label, default, pick, best in suggestions(scene):
        parts.append("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>".format(
            html.escape(label), html.escape(default["value"]) if default else "(per scene)",
            fmt(error_of(default)) if default else "", html.escape(pick["value"]), fmt(error_of(pick)),
            fmt(cost_of(pick), 1), fmt(cost_of(default), 1) if default else ""))
    parts.append("</table>")
    maps_png = map_plots(scene, out_dir)
    if maps_png:
        parts.append(f'<img src="{maps_png}" alt="error maps">')
    parts.append(lag_html(scene, out_dir))
    cols = ["knob", "value", "solution ms", "trace", "AIMs", "gather", "update ms", "AIM RMSE", "IIM RMSE", "IIM p99",
            "IIM worst", "frame RMSE", "frame p99", "frame worst", "frame bias", "per surface", "worst surface",
            "caustic RMSE"]
    parts.append("<h3>Every setting</h3><table><tr>" + "".join(f"<th>{c}</th>" for c in cols) + "</tr>")
    for r in scene["rows"]:
        cells = [r["knob"], r["value"] + (" (default)" if r["default"] else ""), fmt(r["ms"]["solution"], 1),
                 fmt(r["ms"]["trace"], 1), fmt(r["ms"]["aim"], 1), fmt(r["ms"]["gather"], 1),
                 fmt(r["ms"]["update"], 2), fmt(r["aim"]["rmse"]), fmt(r["iim"]["rmse"]), fmt(r["iim"]["p99"]),
                 fmt(r["iim"]["worst"]), fmt(r["frame"]["rmse"]), fmt(r["frame"]["p99"]), fmt(r["frame"]["worst"]),
                 fmt(r["frame_bias"]), fmt(r.get("frame_surface_rms")), fmt(r.get("frame_surface_worst")),
                 fmt(caustic_error(r))]
        parts.append("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
    parts.append("</table>")
    return "\n".join(parts)


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    out_dir, quiet = argv[1], "-q" in argv[2:]
    with open(os.path.join(out_dir, "tradeoff.json")) as f:
        run = json.load(f)
    body = [scene_html(s, out_dir) for s in run["scenes"]]
    page = f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>lmgi tradeoff</title>
<style>body{{font-family:sans-serif;max-width:1300px;margin:2em auto;}} img{{max-width:100%;}}
table{{border-collapse:collapse;font-size:12px;margin:1em 0;}} td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right;}}
th{{background:#eee;}}</style></head><body>
<h1>What accuracy costs in time</h1>
<p>{'Quick sweep' if run['quick'] else 'Full sweep'}; times are medians of {run['repeats']} runs; errors against the
path-traced reference (relative standard error {run['reference_target_error']:g} per entry, which is also about
the smallest relative RMSE a setting can show). AIM and IIM over the valid texels, the frame over the pixels
<code>lmgi check</code> compares. docs/tradeoff.md says what each knob buys and costs.</p>
{''.join(body)}
</body></html>
"""
    with open(os.path.join(out_dir, "report.html"), "w") as f:
        f.write(page)
    if not quiet:
        print(f"wrote {os.path.join(out_dir, 'report.html')}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
