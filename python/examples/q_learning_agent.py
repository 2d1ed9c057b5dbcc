"""An agent that learns the user's goal from ErrP feedback alone: tabular
Q-learning in the Gymnasium grid environment (errp/Grid-v0).

    python python/examples/q_learning_agent.py [--episodes 60] [--goal 3 1] [--seed 0]

The agent never sees the goal. After each action the synthetic user judges
it (an error if it does not bring the cursor closer to the goal, or says
"goal reached" elsewhere), the testbed's decoder reads the EEG of that
judgement, and the reward is the decoded feedback 1 - 2 p(error). With the
decoder at 74 % accuracy the feedback is wrong about one time in four, yet
the greedy policy learns to walk to the goal and stop there.
"""

import argparse

import gymnasium as gym
import numpy as np

import errp.gym  # noqa: F401  (registers errp/Grid-v0)


def greedy_walk(q, start, limit=12):
    """The greedy policy's path from `start`: cells until it says "goal
    reached" (or `limit` steps)."""
    moves = {0: (0, 1), 1: (0, -1), 2: (-1, 0), 3: (1, 0)}
    x, y = start
    path = [(x, y)]
    for _ in range(limit):
        a = int(np.argmax(q[x, y]))
        if a == 4:
            return path, True
        dx, dy = moves[a]
        x, y = min(max(x + dx, 0), 4), min(max(y + dy, 0), 4)
        path.append((x, y))
    return path, False


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=60)
    ap.add_argument("--goal", type=int, nargs=2, default=(3, 1))
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--accuracy", type=float, default=0.7438)
    args = ap.parse_args()

    env = gym.make("errp/Grid-v0", goal=tuple(args.goal), accuracy=args.accuracy)
    rng = np.random.default_rng(args.seed)
    q = np.zeros((5, 5, 5))
    alpha, gamma = 0.2, 0.9
    successes = []
    for episode in range(args.episodes):
        obs, info = env.reset(seed=args.seed + episode)
        epsilon = max(0.05, 0.5 * (1 - episode / (0.7 * args.episodes)))
        done = False
        while not done:
            x, y = obs["cursor"]
            a = int(rng.integers(5)) if rng.random() < epsilon else int(np.argmax(q[x, y]))
            obs, reward, terminated, truncated, info = env.step(a)
            nx, ny = obs["cursor"]
            target = reward + (0.0 if terminated else gamma * q[nx, ny].max())
            q[x, y, a] += alpha * (target - q[x, y, a])
            done = terminated or truncated
        successes.append(info.get("success", False))
        if (episode + 1) % 10 == 0:
            print(f"episodes {episode - 8:3d}-{episode + 1:3d}: "
                  f"{np.mean(successes[-10:]):4.0%} said 'goal reached' on the goal")

    reached = 0
    for start in [(x, y) for x in range(5) for y in range(5)]:
        path, stops = greedy_walk(q, start)
        reached += stops and path[-1] == tuple(args.goal)
    print(f"The learnt greedy policy walks to {tuple(args.goal)} and stops there from "
          f"{reached} of 25 start cells (the goal was never shown to the agent).")


if __name__ == "__main__":
    main()
