#!/usr/bin/env bash
# Checks the cluster files of deploy/ (issue 20): the Slurm scripts parse (bash -n), and the
# Kubernetes manifest validates against the Kubernetes 1.31 schemas, strictly (no unknown
# fields), with the pinned `kubernetes-validate` (Apache-2.0, PyPI) in deploy/.venv.
# The Slurm scripts themselves run in tests/slurm.rs on a local one-node Slurm.
set -euo pipefail
cd "$(dirname "$0")/.."
for f in deploy/slurm/*.sh deploy/slurm/*.sbatch; do
  bash -n "$f"
done
venv=deploy/.venv
if [ ! -x "$venv/bin/kubernetes-validate" ]; then
  python3 -m venv "$venv"
  "$venv/bin/pip" install -q --disable-pip-version-check kubernetes-validate==1.31.0
fi
"$venv/bin/kubernetes-validate" --strict --kubernetes-version 1.31.0 deploy/k8s/*.yaml
echo "check-deploy: deploy/slurm parses, deploy/k8s validates against Kubernetes 1.31"
