"""Where the bundled data folders are: in an installed wheel or in the source tree.

The repository keeps its data under ``data/<name>/`` (with provenance) and
its report templates under ``reports/templates/``; a wheel carries the same
folders as ``stochpound/_data/<name>/`` (``pyproject.toml`` force-includes
them). Editable installs and source checkouts read the repository's copy.
"""

from __future__ import annotations

import importlib.resources
from functools import lru_cache
from pathlib import Path


@lru_cache(maxsize=None)
def bundled_data_dir(name: str, marker: str, repository_folder: str = "data") -> Path | None:
    """The folder of bundled data set ``name`` that contains file ``marker``, or None.

    Parameters
    ----------
    name : str
        The folder's name in the wheel (``stochpound/_data/<name>``) and in the repository.
    marker : str
        A file the folder must contain.
    repository_folder : str
        The repository's top-level folder that holds ``<name>`` (``data``, ``reports``).
    """
    try:
        packaged = importlib.resources.files("stochpound").joinpath("_data", name)
        if packaged.is_dir() and packaged.joinpath(marker).is_file():
            return Path(str(packaged))
    except (ModuleNotFoundError, TypeError, NotADirectoryError, FileNotFoundError):
        pass
    repository = Path(__file__).resolve().parents[1] / repository_folder / name
    if (repository / marker).is_file():
        return repository
    return None
