import OverlaysModule from "diagram-js/lib/features/overlays";
import RulesModule from "diagram-js/lib/features/rules";
import KeyboardModule from "diagram-js/lib/features/keyboard";

import GameBar from "./GameBar";
import GameLock from "./GameLock";
import TokenGameMode from "./TokenGameMode";

export default {
  __depends__: [OverlaysModule, RulesModule, KeyboardModule],
  __init__: ["tokenGame", "gameBar", "gameLock"],
  tokenGame: ["type", TokenGameMode],
  gameBar: ["type", GameBar],
  gameLock: ["type", GameLock],
};
