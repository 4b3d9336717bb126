"""The colour-ball detector's search frame (hsv/search.py): half resolution from 320 px wide, written into
buffers kept from frame to frame, and the same candidates whatever the buffers held before."""

from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pilot_synth as synth

from pilot.common.config import HsvConfig
from pilot.vision.hsv.colour import ColourMask
from pilot.vision.hsv.detector import HsvBlobDetector
from pilot.vision.hsv.search import BUFFERS_KEPT, SEARCH_MIN_WIDTH, SearchFrames


def ball_frame(w: int, h: int, cx: int, cy: int, r: int) -> np.ndarray:
    return synth.red_disc(synth.background(w, h), cx, cy, r)


def test_a_wide_frame_is_searched_at_half_resolution_in_kept_buffers() -> None:
    frames = SearchFrames(ColourMask(HsvConfig()))
    img = ball_frame(SEARCH_MIN_WIDTH, 240, 160, 120, 20)
    small, _, hsv = frames.search(img, 2)
    assert small.shape == (120, 160, 3) and hsv.shape == (120, 160, 3)
    second = ball_frame(SEARCH_MIN_WIDTH, 240, 100, 100, 15)
    again, _, hsv_again = frames.search(second, 2)
    assert again is small and hsv_again is hsv  # written into, not allocated
    expected = cv2.cvtColor(cv2.resize(second, (160, 120), interpolation=cv2.INTER_AREA), frames.colour.code)
    assert np.array_equal(hsv_again, expected)
    smoothed, _, _ = frames.search(img, 2, look=1)
    assert smoothed is not small  # the smoothed look keeps the first look's frame intact


def test_a_narrow_frame_is_searched_as_it_is() -> None:
    frames = SearchFrames(ColourMask(HsvConfig()))
    img = ball_frame(SEARCH_MIN_WIDTH - 1, 200, 100, 100, 20)
    small, _, hsv = frames.search(img, 1)
    assert small is img and hsv.shape == img.shape


def test_sizes_changing_keep_the_buffers_bounded() -> None:
    frames = SearchFrames(ColourMask(HsvConfig()))
    for w in range(320, 320 + 40 * BUFFERS_KEPT, 40):
        frames.search(ball_frame(w, 240, 100, 100, 20), 2)
        frames.mask_buffers((w // 2, 120))
        assert len(frames._buffers) <= BUFFERS_KEPT


def test_the_candidates_do_not_depend_on_earlier_frames() -> None:
    """One detector fed frames of several sizes in turn finds what a fresh detector finds in each."""
    kept = HsvBlobDetector()
    frames = [ball_frame(w, h, w // 3, h // 2, r) for w, h, r in
              ((320, 240, 18), (640, 480, 30), (200, 150, 12), (320, 240, 25), (160, 120, 10), (640, 480, 22))]
    for img in frames * 2:
        got = [dataclasses.astuple(c) for c in kept.candidates(img)]
        assert got == [dataclasses.astuple(c) for c in HsvBlobDetector().candidates(img)]
        assert got and got[0][3] >= 0.6
