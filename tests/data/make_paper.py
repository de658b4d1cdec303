"""Write tests/data/paper.png: a 64x48 cream paper with fine grain (the image-background golden scene).

Run:  python tests/data/make_paper.py
"""
from pathlib import Path

import imageio.v3 as iio
import numpy as np
from scipy import ndimage

rng = np.random.default_rng(7)
grain = ndimage.gaussian_filter(rng.standard_normal((48, 64)), 1.0)
grain = (grain - grain.mean()) / grain.std()
paper = np.clip(np.array([0.95, 0.92, 0.86]) + 0.02 * grain[..., None], 0, 1)
iio.imwrite(Path(__file__).with_name("paper.png"), (paper * 255 + 0.5).astype(np.uint8))
