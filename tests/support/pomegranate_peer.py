#!/usr/bin/python3
"""The same HMM in pomegranate (Debian python3-pomegranate 0.14), an
independent implementation: reads {"model": <skelgraph-hmm JSON>,
"sequences": [[[...], ...], ...]} and writes {"log_probability": [...],
"viterbi": [[state, ...], ...], "viterbi_log_probability": [...]}.
Usage: pomegranate_peer.py IN.json OUT.json"""
import json
import sys

import numpy as np
from pomegranate import (GeneralMixtureModel, HiddenMarkovModel,
                         MultivariateGaussianDistribution)

src = json.load(open(sys.argv[1]))
m = src["model"]
n = m["states"]
dists = []
for e in m["emissions"]:
    comps = [MultivariateGaussianDistribution(np.array(mu, dtype=float), np.array(cov, dtype=float))
             for mu, cov in zip(e["means"], e["covariances"])]
    if len(comps) == 1:
        dists.append(comps[0])
    else:
        dists.append(GeneralMixtureModel(comps, weights=np.array(e["weights"], dtype=float)))
names = ["s%03d" % i for i in range(n)]  # baked models sort states by name: keep our order
model = HiddenMarkovModel.from_matrix(np.array(m["transitions"], dtype=float), dists,
                                      np.array(m["start"], dtype=float), state_names=names, merge="None")
index = {name: i for i, name in enumerate(names)}
out = {"log_probability": [], "viterbi": [], "viterbi_log_probability": []}
for seq in src["sequences"]:
    x = np.array(seq, dtype=float)
    out["log_probability"].append(float(model.log_probability(x)))
    lp, path = model.viterbi(x)
    out["viterbi_log_probability"].append(float(lp))
    out["viterbi"].append([index[s.name] for _, s in path if s.name in index])
json.dump(out, open(sys.argv[2], "w"))
