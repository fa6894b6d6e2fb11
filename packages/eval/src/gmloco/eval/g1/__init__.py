# SPDX-License-Identifier: Apache-2.0
"""The G1 on MPM sand: evaluation config, episode loop, time box, scoring, policy, recordings and GPU queue."""
