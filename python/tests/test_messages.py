"""Errors in Python terms: a wrong type or value given to a public function is answered naming
the keyword (or the quantity), what it takes and what was given — never with the extension's
extraction text ("failed to extract enum PixelArg ('Square | Pair | List')") — and a file's
choices (series, channels by name, planes) come in one message."""

import json

import numpy as np
import pytest

import contactscope as cs
from test_vendor import sample

HEIGHTS = np.zeros((64, 64))


def message(call):
    with pytest.raises((TypeError, ValueError)) as e:
        call()
    text = str(e.value)
    assert "failed to extract" not in text and "PixelArg" not in text, text
    assert "\n" not in text, text
    return e.type, text


@pytest.mark.parametrize("call, kind, words", [
    (lambda: cs.simulate(HEIGHTS, "200nm", 3.7e9, [1e-3]), TypeError,
     ["pixel size must be a number of metres", "got str '200nm'", "parse_pixel_size('200nm')"]),
    (lambda: cs.simulate(HEIGHTS, [1e-7, 2e-7, 3e-7], 3.7e9, [1e-3]), cs.InputError,
     ["one number or two (x, y); got 3"]),
    (lambda: cs.simulate(HEIGHTS, 2e-7, "3.7GPa", [1e-3]), TypeError,
     ["modulus= must be a number in Pa", "got str '3.7GPa'"]),
    (lambda: cs.simulate(HEIGHTS, 2e-7, 3.7e9, "1mN"), TypeError,
     ["loads= must be a sequence of numbers in N", "parse_forces('1mN')"]),
    (lambda: cs.simulate(HEIGHTS, 2e-7, 3.7e9, [1e-3, "2mN"]), TypeError,
     ["loads=", "item 1 is str '2mN'"]),
    (lambda: cs.simulate(HEIGHTS, 2e-7, 3.7e9, [1e-3], maps=3), TypeError,
     ['maps= must be "none", "contact" or "all"; got int 3']),
    (lambda: cs.simulate(HEIGHTS, 2e-7, 3.7e9, [1e-3], model="Hardening", k=4e15),
     cs.InputError, ['model="Hardening" is not one of', 'did you mean "hardening"?']),
    (lambda: cs.simulate(HEIGHTS, 2e-7, 3.7e9, [1e-3], model="plastic"), cs.InputError,
     ['model="plastic" is not one of "elastic", "hardness", "hardening", "gt"']),
    (lambda: cs.analyze(np.ones((1, 8, 8), np.uint16), forces="4mN"), TypeError,
     ["forces= must be a sequence of numbers in N", "parse_forces('4mN')"]),
    (lambda: cs.analyze(np.ones((1, 8, 8), np.uint16), method=[1]), TypeError,
     ['method= must be "otsu", "per-image" or a threshold', "got list of 1"]),
    (lambda: cs.read_series(["a.tif"], channel=1.5), TypeError,
     ["channel= must be an index (an int ≥ 0), a channel's name (a str) or None",
      "got float 1.5"]),
    (lambda: cs.read_series(["a.tif"], series="one"), TypeError,
     ["series= must be an int ≥ 0 or None", "got str 'one'"]),
    (lambda: cs.read_series(["a.tif"], z=-1), ValueError, ["z= must be ≥ 0; got -1"]),
    (lambda: cs.read_series(["a.tif"], t=True), TypeError,
     ["t= must be an int ≥ 0 or None", "got bool True"]),
    (lambda: cs.read_series(["a.tif"], axes=["H", 0]), TypeError,
     ["axes= must be a dict of axis names to indices"]),
    (lambda: cs.read_series(3), TypeError, ["the files must be a path", "got int 3"]),
    (lambda: cs.read_topography(3), TypeError, []),
    (lambda: cs.hertz("squeeze.csv", "290um"), TypeError,
     ["radius= must be a number in m", "parse_pixel_size('290um')"]),
])
def test_wrong_types_are_answered_in_python_terms(call, kind, words):
    raised, text = message(call)
    assert issubclass(raised, kind), (raised, text)
    for w in words:
        assert w in text, (w, text)


def test_a_files_choices_come_in_one_message_and_channels_by_name():
    nd2 = sample("nd2/cluster.nd2")
    with pytest.raises(cs.InputError) as e:
        cs.read_image(nd2)
    text = str(e.value)
    assert ("2 channels, 10 z planes and 3 time points; choose one of each with channel=0..1 "
            "or a name (0 '5-FAM/pH 9.0', 1 'FM 4-64/2% CHAPS'), z=0..9 and t=0..2") in text, text
    by_index = cs.read_image(nd2, channel=1, z=4, t=2).images
    by_name = cs.read_image(nd2, channel="FM 4-64/2% CHAPS", z=4, t=2).images
    np.testing.assert_array_equal(by_index, by_name)
    with pytest.raises(cs.InputError, match="no channel has that name; the channels are 0 "):
        cs.read_image(nd2, channel="AF488", z=4, t=2)
    # info lists the names the selection takes.
    names = [c["name"] for c in cs.info(nd2)["series"][0]["channels"]]
    assert names == ["5-FAM/pH 9.0", "FM 4-64/2% CHAPS"]


def test_a_tiff_channel_is_chosen_by_index(tmp_path):
    path = tmp_path / "one.tif"
    cs.write_tiff(path, np.arange(16, dtype=np.uint16).reshape(1, 4, 4))
    # Names come from OME-XML; a TIFF without them is chosen by index.
    with pytest.raises(cs.InputError, match="have no names; choose by index"):
        cs.read_image(path, channel="AF488")
    assert cs.read_image(path, channel=0).images.shape == (1, 4, 4)


def test_a_folder_written_from_python_says_how_it_was_made(tmp_path):
    series = cs.synth_series(width=128, height=128, forces=[4e-3, 6e-3, 10e-3], seed=3)
    out = tmp_path / "run"
    cs.analyze(series["images"], forces=[4e-3, 6e-3, 10e-3], pixel_size=2e-7, out=out)
    words = json.loads((out / "summary.json").read_text())["command_line"]
    assert len(words) == 2 and words[1] == f"contactscope.analyze(…, out={str(out)!r})", words
    given = tmp_path / "given"
    cs.analyze(series["images"], forces=[4e-3, 6e-3, 10e-3], pixel_size=2e-7, out=given,
               command_line=["contactscope", "analyze", "x"])
    words = json.loads((given / "summary.json").read_text())["command_line"]
    assert words == ["contactscope", "analyze", "x"]

