"""Initial conditions on a section grid and their perturbed copies (basin maps, uncertainty algorithm)."""

import numpy as np
import pytest

from hhscatter.model import HenonHeiles
from hhscatter.scene.ics import perturbed_on_section, section_grid

M = HenonHeiles()


def test_section_grid_cells_states_and_mapping():
    x, y, allowed, states, cell = section_grid(M, 0.25, (-1, 1, -1, 1), (40, 50))
    assert x.shape == (50,) and y.shape == (40,) and allowed.shape == (40, 50)
    np.testing.assert_allclose(np.diff(x), 2 / 50)
    assert x[0] == pytest.approx(-1 + 1 / 50) and y[-1] == pytest.approx(1 - 1 / 40)
    # every allowed cell has a state at its centre, on the section and the energy shell
    assert len(states) == allowed.sum() == len(cell)
    X, Y = np.meshgrid(x, y)
    np.testing.assert_array_equal(states[:, 0], X.flat[cell])
    np.testing.assert_array_equal(states[:, 1], Y.flat[cell])
    np.testing.assert_allclose(M.energy(*states.T), 0.25, atol=1e-15)
    assert np.abs(states[:, 0] * states[:, 2] + states[:, 1] * states[:, 3]).max() < 1e-15
    assert (states[:, 0] * states[:, 3] - states[:, 1] * states[:, 2] > 0).all()
    # and the forbidden cells are exactly those with V ≥ E
    np.testing.assert_array_equal(~allowed, M.potential(X, Y) >= 0.25)
    with pytest.raises(ValueError, match="extent"):
        section_grid(M, 0.25, (1, -1, -1, 1), (4, 4))
    with pytest.raises(ValueError, match="shape"):
        section_grid(M, 0.25, (-1, 1, -1, 1), (0, 4))


def test_perturbed_copies_stay_on_the_section_and_shell():
    _, _, _, states, _ = section_grid(M, 0.3, (-1, 1, -1, 1), (30, 30))
    out, ok = perturbed_on_section(M, states, 0.3, dx=1e-6)
    assert ok.mean() > 0.99 and np.isnan(out[~ok]).all()
    np.testing.assert_allclose(out[ok, 0], states[ok, 0] + 1e-6)
    np.testing.assert_array_equal(out[ok, 1], states[ok, 1])
    np.testing.assert_allclose(M.energy(*out[ok].T), 0.3, atol=1e-15)
    assert np.abs(out[ok, 0] * out[ok, 2] + out[ok, 1] * out[ok, 3]).max() < 1e-15
    # a move into the wall below the well (V(x, −1.5) ≈ 2.2 > E) is flagged
    near = section_grid(M, 0.3, (0.05, 0.15, 0.05, 0.15), (3, 3))[3]
    wall, ok2 = perturbed_on_section(M, near, 0.3, dy=-1.6)
    assert not ok2.any() and np.isnan(wall).all()
