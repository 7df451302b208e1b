# The Python package friction_sim (src/friction_sim): catkin_python_setup() installs it, and the devel
# space puts it on PYTHONPATH. Not for running by hand.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["friction_sim"], package_dir={"": "src"}))
