import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from study_copy import REPO_STUDIES, copy_study_folder

#: The one profile of the property tests: the same examples on every run (derandomized, no example database), no
#: deadline (the machines are shared, timings vary), and the health checks that fail a slow or fixture-using but
#: correct test turned off. A module sets only its number of examples: ``settings(max_examples=n)`` inherits the
#: rest from this profile.
settings.register_profile(
    "hhscatter",
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture, HealthCheck.data_too_large],
)
settings.load_profile("hhscatter")

EPS = np.finfo(float).eps


@pytest.fixture(scope="session")
def cons_scene():
    from hhscatter.scene.scene import Scene

    return Scene(energy=0.27, n=400, seed=11, chunk_size=150)


@pytest.fixture(scope="session")
def diss_scene():
    from hhscatter.scene.scene import Scene, SectionWindow

    return Scene(
        energy=0.3,
        gamma=0.01,
        n=300,
        seed=12,
        chunk_size=120,
        sections=SectionWindow(t_from=5.0, t_to=40.0),
        snapshots=tuple(np.arange(0.0, 100.0, 10.0)),
    )


@pytest.fixture
def copy_study():
    """copy_study(name, root, edit=None) -> a copy of a study folder of the repository in the studies folder root."""
    return copy_study_folder


@pytest.fixture(scope="session")
def tiny_studies(tmp_path_factory):
    """A studies root with every study of the repository built at scale 'tiny' from an empty out/,
    one after the other in the order of the declared graph (study.toml [needs]), as `make studies` does."""
    from hhscatter.studies import run_stage
    from hhscatter.studies.graph import studies

    root = tmp_path_factory.mktemp("studies")
    order = [s.name for s in studies(REPO_STUDIES)]
    for name in order:
        copy_study_folder(name, root)
    for name in order:
        run_stage(name, "all", "tiny", workers=1, progress=False, root=root)
    return root
