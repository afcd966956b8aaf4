// The page of python -m pegame.play: draws the map, the person's evader and what the
// game lets the person know (the pursuer's pose and view cone, its belief), and sends
// the person's (v m/s, w rad/s) command from the keyboard or a gamepad (Gamepad API).
// Messages: see pegame/play/server.py. Frames are drawn latest-only in
// requestAnimationFrame: a frame that arrives while an older one waits replaces it.
"use strict";

const KEYS = {
  forward: ["ArrowUp", "w", "W"],
  back: ["ArrowDown", "s", "S"],
  left: ["ArrowLeft", "a", "A"],
  right: ["ArrowRight", "d", "D"],
};
const DEADZONE = 0.15; // gamepad stick values below this count as 0

// The command (v m/s, w rad/s) from the keys held and a gamepad (or null), for an
// evader of top speed v_max and turn rate w_max: keys when any is held, else the
// gamepad's left stick (axes 0, 1; up is negative) or d-pad (buttons 12-15).
function commandFrom(held, pad, evader) {
  const any = (names) => names.some((k) => held.has(k));
  let forward = (any(KEYS.forward) ? 1 : 0) - (any(KEYS.back) ? 1 : 0);
  let turn = (any(KEYS.left) ? 1 : 0) - (any(KEYS.right) ? 1 : 0);
  if (forward === 0 && turn === 0 && pad) {
    const axis = (i) => {
      const value = pad.axes && pad.axes.length > i ? pad.axes[i] : 0;
      return Math.abs(value) < DEADZONE ? 0 : value;
    };
    const pressed = (i) => !!(pad.buttons && pad.buttons[i] && pad.buttons[i].pressed);
    forward = -axis(1) + (pressed(12) ? 1 : 0) - (pressed(13) ? 1 : 0);
    turn = -axis(0) + (pressed(14) ? 1 : 0) - (pressed(15) ? 1 : 0);
  }
  const clip = (x) => Math.max(-1, Math.min(1, x));
  return { v: clip(forward) * evader.v_max, w: clip(turn) * evader.w_max };
}

const pegame = {
  commandFrom,
  framesDrawn: 0,
  conesDrawn: 0,
  conePoint: null, // a canvas point inside the last cone drawn, [x, y] px
  lastFrame: null,
  result: null,
  game: null,
};
window.pegame = pegame;

const canvas = document.getElementById("view");
const ctx = canvas.getContext("2d");
const statusText = document.getElementById("status");
const resultText = document.getElementById("result");
const clock = document.getElementById("clock");
const startButton = document.getElementById("start");
const held = new Set();
let socket = null;
let mapImage = null;
let pending = null; // the newest frame not yet drawn
let sentCommand = { v: 0, w: 0 };
let playing = false;

function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

function sendCommand(stamp) {
  if (!pegame.game || !playing) return;
  const command = commandFrom(held, firstPad(), pegame.game.evader);
  if (command.v === sentCommand.v && command.w === sentCommand.w) return;
  sentCommand = command;
  send({ type: "command", v: command.v, w: command.w, stamp });
}

function firstPad() {
  if (!navigator.getGamepads) return null;
  for (const pad of navigator.getGamepads()) if (pad && pad.connected) return pad;
  return null;
}

function start() {
  if (startButton.disabled) return;
  startButton.disabled = true;
  resultText.textContent = "";
  statusText.textContent = "Starting...";
  send({ type: "start" });
}

// -- drawing: one pixel scale for the map, world (x, y) m -> canvas px

// The canvas sized to the map's shape, as large as the window leaves room for.
function fitCanvas(map) {
  const room = [Math.max(window.innerWidth - 360, 200), Math.max(window.innerHeight - 90, 150)];
  const scale = Math.min(room[0] / map.width, room[1] / map.height);
  canvas.width = Math.round(map.width * scale);
  canvas.height = Math.round(map.height * scale);
}

function layout() {
  const map = pegame.game.map;
  const scale = Math.min(canvas.width / map.width, canvas.height / map.height);
  const toCanvas = (x, y) => [
    ((x - map.origin[0]) / map.resolution) * scale,
    (map.height - (y - map.origin[1]) / map.resolution) * scale,
  ];
  return { map, scale, toCanvas, metres: (m) => (m / map.resolution) * scale };
}

function drawAgent(view, pose, radius, colour) {
  const [cx, cy] = view.toCanvas(pose[0], pose[1]);
  const r = Math.max(view.metres(radius), 3);
  ctx.fillStyle = colour;
  ctx.beginPath();
  ctx.arc(cx, cy, r, 0, 2 * Math.PI);
  ctx.fill();
  ctx.strokeStyle = "#000";
  ctx.beginPath(); // heading: canvas y points down, so the angle is negated
  ctx.moveTo(cx, cy);
  ctx.lineTo(cx + 1.8 * r * Math.cos(pose[2]), cy - 1.8 * r * Math.sin(pose[2]));
  ctx.stroke();
}

// A pursuer's view: the outline of its visibility region (walls hide what is behind
// them), filled; pegame.conePoint is a point inside it, on the optical axis.
function drawCone(view, outline, pose, camera) {
  ctx.fillStyle = "rgba(229, 57, 53, 0.28)";
  ctx.beginPath();
  outline.forEach(([x, y], i) => {
    const [cx, cy] = view.toCanvas(x, y);
    if (i === 0) ctx.moveTo(cx, cy);
    else ctx.lineTo(cx, cy);
  });
  ctx.closePath();
  ctx.fill();
  const axis = outline[Math.floor((outline.length - 9) / 2)]; // the middle ray's end
  const reach = Math.hypot(axis[0] - pose[0], axis[1] - pose[1]);
  const mid = (camera.near + Math.max(reach, camera.near)) / 2;
  pegame.conePoint = view.toCanvas(pose[0] + mid * Math.cos(pose[2]), pose[1] + mid * Math.sin(pose[2]));
  pegame.conesDrawn += 1;
}

function draw(frame) {
  const view = layout();
  const game = pegame.game;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (mapImage && mapImage.complete) {
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(mapImage, 0, 0, view.map.width * view.scale, view.map.height * view.scale);
  }
  if (frame.belief) {
    ctx.fillStyle = "rgba(30, 136, 229, 0.5)";
    for (const [x, y] of frame.belief.particles || []) {
      const [px, py] = view.toCanvas(x, y);
      ctx.fillRect(px - 1, py - 1, 2, 2);
    }
    if (frame.belief.mean) {
      const [mx, my] = view.toCanvas(frame.belief.mean[0], frame.belief.mean[1]);
      ctx.strokeStyle = "#1565c0";
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(mx - 6, my - 6); ctx.lineTo(mx + 6, my + 6);
      ctx.moveTo(mx - 6, my + 6); ctx.lineTo(mx + 6, my - 6);
      ctx.stroke();
      ctx.lineWidth = 1;
    }
  }
  (frame.cones || []).forEach((outline, i) => drawCone(view, outline, frame.pursuers[i], game.camera));
  if (game.show.includes("pursuer")) {
    for (const pose of frame.pursuers || []) drawAgent(view, pose, game.pursuer_radius, "#e53935");
  }
  drawAgent(view, frame.evader, game.evader.radius, "#43a047");
  clock.textContent = `${frame.time.toFixed(1)} / ${game.t_max} s`;
}

function animate() {
  if (playing) sendCommand(performance.timeOrigin + performance.now()); // gamepads are polled
  if (pending && pegame.game) {
    const frame = pending;
    pending = null;
    draw(frame);
    pegame.framesDrawn += 1;
    pegame.lastFrame = frame;
    send({ type: "drawn", sent: frame.sent, drawn: performance.timeOrigin + performance.now() });
  }
  requestAnimationFrame(animate);
}

// -- messages from the server

function onMessage(event) {
  const message = JSON.parse(event.data);
  if (message.type === "game") {
    pegame.game = message;
    pegame.result = null;
    fitCanvas(message.map);
    mapImage = new Image();
    mapImage.src = message.map.image;
    sentCommand = { v: 0, w: 0 };
    playing = true;
    sendCommand(performance.timeOrigin + performance.now()); // keys held from before
    statusText.textContent = `Playing on ${message.map.name}, seed ${message.seed}: escape!`;
    canvas.focus();
  } else if (message.type === "frame") {
    pending = message;
  } else if (message.type === "result") {
    playing = false;
    pegame.result = message;
    const rate = (100 * message.tracking_rate).toFixed(1);
    const seen = (100 * message.visible_rate).toFixed(1);
    resultText.textContent = `Game over: the pursuer tracked you ${rate}% of the time (you were in its view ${seen}%).`;
    statusText.textContent = "Another game?";
    startButton.textContent = "Another game (Enter)";
    startButton.disabled = false;
  } else if (message.type === "failed") {
    playing = false;
    pegame.result = message;
    resultText.textContent = `The game failed: ${message.error}`;
    startButton.disabled = false;
  }
}

function connect() {
  socket = new WebSocket(`ws://${location.host}/ws`);
  let opened = false;
  socket.onopen = () => {
    opened = true;
    statusText.textContent = "Connected. Press Start when ready.";
    startButton.disabled = false;
  };
  socket.onmessage = onMessage;
  socket.onclose = () => {
    playing = false;
    startButton.disabled = true;
    statusText.textContent = opened
      ? "The server closed the game."
      : "Refused: another page is playing this game, or the server has stopped.";
  };
}

function onKey(event, down) {
  if (event.key === "Enter" && down) {
    start();
    return;
  }
  if (event.key === " " && down) {
    held.clear();
  } else if (Object.values(KEYS).some((names) => names.includes(event.key))) {
    if (down) held.add(event.key);
    else held.delete(event.key);
  } else {
    return;
  }
  event.preventDefault();
  sendCommand(performance.timeOrigin + event.timeStamp);
}

document.addEventListener("keydown", (event) => onKey(event, true));
document.addEventListener("keyup", (event) => onKey(event, false));
window.addEventListener("blur", () => {
  held.clear();
  sendCommand(performance.timeOrigin + performance.now());
});
startButton.addEventListener("click", start);
connect();
requestAnimationFrame(animate);
