"""The one thing of the build that pyproject.toml cannot say: the top-level ``presets/``
folder ships inside the package as ``frictionlab.builtin_presets`` (read by
``frictionlab.preset.builtin``), so ``frictionlab run quickstart`` works after any install."""

from setuptools import find_packages, setup

PLUGINS = find_packages("plugins", include=["frictionlab*"])

setup(
    packages=find_packages(".", include=["frictionlab", "frictionlab.*"]) + PLUGINS + ["frictionlab.builtin_presets"],
    package_dir={
        "frictionlab.builtin_presets": "presets",
        **{name: f"plugins/{name}" for name in PLUGINS if "." not in name},
    },
    package_data={"frictionlab.builtin_presets": ["*.yaml"], "frictionlab.tui": ["*.tcss"]},
)
