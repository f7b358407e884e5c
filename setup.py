# The Python package hybrid_vo (python/hybrid_vo) for catkin_python_setup(): the devel space's
# hybrid_vo/__init__.py relays to it, next to the compiled extensions and the generated messages.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["hybrid_vo"], package_dir={"": "python"}))
