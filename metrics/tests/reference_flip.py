"""Mean FLIP of image pairs by flip-evaluator, NVIDIA's implementation (the reference for
kiln-metrics' port); run by flip_evaluator.rs.

Usage: reference_flip.py MODE REFERENCE TEST [MODE REFERENCE TEST ...]

MODE is HDR or LDR; REFERENCE and TEST are .npy files of float32, shape (height, width, 3),
linear RGB. Default parameters; LDR inputs are linear (inputsRGB=False). Prints one line per
pair: the mean error.
"""
import sys

import flip_evaluator
import numpy as np

args = sys.argv[1:]
if len(args) == 0 or len(args) % 3 != 0:
    sys.exit(__doc__)
for mode, ref_path, test_path in zip(args[0::3], args[1::3], args[2::3]):
    ref = np.load(ref_path)
    test = np.load(test_path)
    assert ref.dtype == np.float32 and ref.shape == test.shape and ref.shape[2] == 3, ref_path
    _, mean, params = flip_evaluator.evaluate(
        ref, test, mode, inputsRGB=False, applyMagma=False, computeMeanError=True
    )
    print(repr(float(mean)), flush=True)
    print(f"{ref_path}: {mode} {params}", file=sys.stderr)
