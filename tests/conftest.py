import numpy as np
import pytest

EPS = np.finfo(float).eps


@pytest.fixture(scope="session")
def cons_scene():
    from hhscatter.scene import Scene

    return Scene(energy=0.27, n=400, seed=11, chunk_size=150)


@pytest.fixture(scope="session")
def diss_scene():
    from hhscatter.scene import Scene, SectionWindow

    return Scene(energy=0.3, gamma=0.01, n=300, seed=12, chunk_size=120,
                 sections=SectionWindow(t_from=5.0, t_to=40.0), snapshots=tuple(np.arange(0.0, 100.0, 10.0)))
