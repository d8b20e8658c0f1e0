#!/usr/bin/python3
"""Merges the results of a Caliper job array (launch/caliper slurm batch --array K) into the
layout one batch gives: OUTDIR/runs/NAME.csv and OUTDIR/summary.csv, the runs in the experiment
file's order (OUTDIR/array/names.txt). Each array task wrote OUTDIR/tasks/ROUND-TASK/runs/ and
summary.csv (caliper-ctl batch). A run counts when a summary says `done` and its CSV is there;
the first such result is kept (a later round only ran what was missing). A run that failed (a
physics fault: running it again gives the same) stays `failed`; a run with no result is listed
`missing` (its last task's status and reason, if any) in the summary and in
OUTDIR/array/missing.txt. Exit 0 when every run is done, 1 otherwise (then `launch/caliper slurm
rerun OUTDIR` runs only what is missing)."""
import csv
import glob
import os
import shutil
import sys


def read_summary(path):
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        return header, [row for row in reader if row]


def main(out):
    names_file = os.path.join(out, "array", "names.txt")
    with open(names_file) as f:
        names = [line.strip() for line in f if line.strip()]
    header = None
    done, other = {}, {}
    sources = []
    # a previous merge (or the single job that a rerun completes) comes first
    if os.path.exists(os.path.join(out, "summary.csv")):
        sources.append(out)
    sources += sorted(glob.glob(os.path.join(out, "tasks", "*")),
                      key=lambda d: [int(p) if p.isdigit() else p
                                     for p in os.path.basename(d).split("-")])
    for src in sources:
        summary = os.path.join(src, "summary.csv")
        if not os.path.exists(summary):
            continue
        h, rows = read_summary(summary)
        header = header or h
        for row in rows:
            name, status = row[0], row[1]
            run = os.path.join(src, "runs", name + ".csv")
            if status == "done" and os.path.exists(run):
                done.setdefault(name, (src, row))
            else:
                other[name] = row
    if header is None:
        header = ["name", "status", "model", "attempts", "duration [s]", "steps", "samples",
                  "wall_time [s]", "load_wall_time [s]", "step_wall_time [s]", "retries",
                  "reason"]
    os.makedirs(os.path.join(out, "runs"), exist_ok=True)
    missing, failed = [], []
    tmp = os.path.join(out, "summary.csv.tmp")
    with open(tmp, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(header)
        for name in names:
            if name in done:
                src, row = done[name]
                target = os.path.join(out, "runs", name + ".csv")
                if os.path.abspath(src) != os.path.abspath(out):
                    shutil.copyfile(os.path.join(src, "runs", name + ".csv"), target + ".tmp")
                    os.replace(target + ".tmp", target)
                writer.writerow(row)
            elif name in other and other[name][1] == "failed":
                # a physics fault, or a run that took every Model it was given down: running it
                # again gives the same, so it stays failed with its reason
                failed.append(name)
                writer.writerow(other[name])
            else:
                missing.append(name)
                row = list(other.get(name, [name]))
                row += [""] * (len(header) - len(row))
                if len(row) < 2 or row[1] != "missing":  # said once, not again at each merge
                    why = row[1] if len(row) > 1 and row[1] else "never run"
                    row[1] = "missing"
                    row[-1] = (f"{why}: " + row[-1]) if row[-1] else why
                writer.writerow(row[:len(header)])
    os.replace(tmp, os.path.join(out, "summary.csv"))
    # what `launch/caliper slurm rerun` submits again
    with open(os.path.join(out, "array", "missing.txt"), "w") as f:
        f.writelines(name + "\n" for name in missing)
    print(f"merged {len(names) - len(missing) - len(failed)} of {len(names)} runs into "
          f"{out}/runs, summary {out}/summary.csv")
    if failed:
        shown = ", ".join(failed[:10]) + (" ..." if len(failed) > 10 else "")
        print(f"failed {len(failed)} (their reasons in the summary; not run again): {shown}")
    if missing:
        shown = ", ".join(missing[:10]) + (" ..." if len(missing) > 10 else "")
        print(f"missing {len(missing)}: {shown}")
        print(f"run only these again: launch/caliper slurm rerun {out}")
        return 1
    return 1 if failed else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: merge.py OUTDIR")
    sys.exit(main(sys.argv[1]))
