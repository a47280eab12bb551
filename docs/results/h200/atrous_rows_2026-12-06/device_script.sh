#!/usr/bin/env bash
# Seventh session, last short try: the a-trous variants' ncu split on Sponza and their GPU denoise tests.
set -u
cd "$(dirname "$0")/.."
tar -C .gpu -xJf .gpu/bin.tar.xz
export PVR_SCENES=$PWD/.scenes
o=$OUT/r; mkdir -p $o
pack() { tar -C $OUT -czf $OUT/results.tgz r; }
trap pack EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv > $o/gpu.txt 2>&1
step() { local name=$1 t=$2; shift 2; local s=$SECONDS; timeout $t "$@" > $o/$name.txt 2>&1; echo "$name rc=$? $((SECONDS-s)) s" | tee -a $o/steps.txt; pack; }
for variant in 0 2 1; do
  PVR_ATROUS_VARIANT=$variant step ncu_variant$variant 60 ncu --clock-control none --target-processes all -k regex:"accumulateKernel|varianceKernel|atrous" --launch-skip 70 -c 14 --csv --page raw --metrics gpu__time_duration.sum,launch__registers_per_thread .gpu/run.sh .gpu/bin/photonvr render scenes/dabrovic-sponza.json --backend cuda --photons 512x512 --denoise --trajectory .scenes/sponza_walk8.traj --out /tmp/ncu --radius 0.15
done
for variant in 2 1; do
  PVR_ATROUS_VARIANT=$variant step gpu_tests_variant$variant 40 .gpu/run.sh .gpu/bin/pvr_gpu_tests --gtest_filter='*Denois*'
done
