"""Faces of pkm for learning stacks: batched simulators that run pkm's exact closed loops inside their step.

:mod:`pkm.learn.mjwarp`: N worlds of a robot's serial-equivalent model in MuJoCo Warp, its transmissions applied
inside the step by pkm's Warp kernels (``pip install "pkm-robotics[mjwarp]"``). Nothing here is imported by
``import pkm``; the core (:mod:`pkm.core`) imports nothing from here.
"""
