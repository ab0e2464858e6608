"""Prints the events of the fricont CLI's JSON (SPEC §8) in the plain text form of
trace_case.c, so that tests-install/run.sh can compare the CLI with the C interface."""
import json
import sys

d = json.load(open(sys.argv[1]))
print("start %.17g %.3e" % (d["start"]["alpha"], d["start"].get("residual", 0.0)))
for k, e in enumerate(d["events"]):
    print("event %d %d %.17g %d %s %s %d %d" % (
        e["index"], e.get("transition", k + 1), e["alpha"], e["node"], e["from"], e["to"],
        int(e["fold"]), int(e["bifurcation"])))
print("end %s %d" % (d["end"]["reason"], len(d["pieces"])))
