// The commissioning page: polls /api/status, redraws the live view with the result's overlay,
// and sends the actions and settings with the session's CSRF token.
'use strict';

const page = { csrf: '', loggedIn: false, loginPossible: false, shownResult: -1, status: null,
               settings: [] };
const colours = ['#ff5252', '#40c4ff', '#69f0ae', '#ffd740', '#e040fb', '#ff6e40', '#b2ff59',
                 '#18ffff'];

function $(id) { return document.getElementById(id); }

function say(id, text, ok) {
  const el = $(id);
  el.textContent = text;
  el.classList.toggle('error', !ok);
}

async function post(path, body) {
  const response = await fetch(path, {
    method: 'POST', body: body || '', credentials: 'same-origin',
    headers: { 'X-CSRF-Token': page.csrf, 'Content-Type': 'text/plain' } });
  let answer = { ok: false, message: response.statusText };
  try { answer = await response.json(); } catch (e) { /* not JSON: keep the status text */ }
  return answer;
}

async function action(path, body) {
  const answer = await post(path, body);
  say('message', answer.message, answer.ok);
  return answer;
}

function drawView(canvasId, image, result, side) {
  const canvas = $(canvasId);
  if (canvas.width !== image.width || canvas.height !== image.height) {
    canvas.width = image.width;
    canvas.height = image.height;
  }
  const g = canvas.getContext('2d');
  g.drawImage(image, 0, 0);
  const full = result.image_size[side][0] || image.width;
  const scale = image.width / full;
  const dashed = (lines, colour) => {
    g.strokeStyle = colour;
    g.setLineDash([6, 4]);
    g.lineWidth = 1;
    for (const line of lines) {
      g.beginPath();
      for (let k = 0; k + 1 < line.length; k += 2) {
        if (k === 0) g.moveTo(line[k] * scale, line[k + 1] * scale);
        else g.lineTo(line[k] * scale, line[k + 1] * scale);
      }
      g.stroke();
    }
    g.setLineDash([]);
  };
  if ($('show-table').checked && page.status.table_plane) {
    dashed(page.status.table_plane[side], 'rgba(255,215,64,0.6)');
  }
  if ($('show-volume').checked && page.status.volume) {
    dashed(page.status.volume[side], 'rgba(255,255,255,0.7)');
  }
  g.lineWidth = 2;
  g.font = '14px sans-serif';
  result.objects.forEach((o, i) => {
    g.strokeStyle = colours[i % colours.length];
    g.fillStyle = g.strokeStyle;
    let sx = 0, sy = 0, n = 0;
    for (const line of o.lines[side]) {
      g.beginPath();
      for (let k = 0; k + 1 < line.length; k += 2) {
        const x = line[k] * scale, y = line[k + 1] * scale;
        if (k === 0) g.moveTo(x, y); else g.lineTo(x, y);
        sx += x; sy += y; n += 1;
      }
      g.stroke();
    }
    if (n > 0) {
      const label = (o.name || ('model ' + o.model_id)) + ' ' + o.score.toFixed(2);
      const w = g.measureText(label).width;
      // At the object's centre, kept inside the image.
      const x = Math.max(2, Math.min(sx / n, canvas.width - w - 4));
      const y = Math.max(16, Math.min(sy / n, canvas.height - 4));
      g.fillStyle = 'rgba(0,0,0,0.6)';
      g.fillRect(x - 2, y - 14, w + 4, 18);
      g.fillStyle = colours[i % colours.length];
      g.fillText(label, x, y);
    }
  });
}

function loadImage(side, count) {
  return new Promise((resolve) => {
    const image = new Image();
    image.onload = () => resolve(image);
    image.onerror = () => resolve(null);
    image.src = '/api/image?side=' + side + '&n=' + count;
  });
}

async function refreshLive(result) {
  if (!result.has_images || result.count === page.shownResult) return;
  page.shownResult = result.count;
  const sides = $('sides').value;
  for (const [side, name] of [[0, 'left'], [1, 'right']]) {
    const wanted = sides === 'both' || sides === name;
    $('fig-' + name).hidden = !wanted;
    if (!wanted || result.image_size[side][0] === 0) continue;
    const image = await loadImage(name, result.count);
    if (image) drawView('view-' + name, image, result, side);
  }
}

function row(cells) {
  const tr = document.createElement('tr');
  for (const c of cells) {
    const td = document.createElement('td');
    td.textContent = c;
    tr.appendChild(td);
  }
  return tr;
}

function showResults(result) {
  const age = result.age_ms < 0 ? 'none yet' : (result.age_ms / 1000).toFixed(1) + ' s ago';
  $('result-summary').textContent =
      'set ' + result.sequence + ' (' + result.status + '), ' + result.objects.length +
      ' objects, trigger to result ' + (result.latency_us / 1000).toFixed(1) + ' ms, poses in the ' +
      result.output_frame + ' frame, table ' + result.table + ', ' + age;
  const st = result.stages_ms;
  $('stages').textContent = st.total > 0
      ? 'stages: features ' + st.features.toFixed(1) + ' ms, stereo ' + st.stereo.toFixed(1) +
        ' ms, hashing ' + st.hashing.toFixed(1) + ' ms, verification ' + st.verify.toFixed(1) +
        ' ms, refinement ' + st.refine.toFixed(1) + ' ms, total ' + st.total.toFixed(1) + ' ms'
      : 'stages: not measured for this result';
  const body = $('objects');
  body.replaceChildren();
  for (const o of result.objects) {
    body.appendChild(row([o.name || ('model ' + o.model_id), o.score.toFixed(3),
                          o.t_mm.map((v) => v.toFixed(1)).join(' '),
                          o.q_wxyz.map((v) => v.toFixed(4)).join(' ')]));
  }
}

function showHealth(h) {
  $('state').textContent = h.state;
  $('state').className = 'badge ' + h.state;
  const rows = [
    ['state', h.state + ' (fault causes 0x' + h.fault_bits.toString(16) + ')'],
    ['NMT', h.nmt + ', node ' + h.node_id + ', error register 0x' + h.error_register.toString(16)],
    ['heartbeat', h.heartbeat_ms + ' ms, ' + h.counters.heartbeats + ' sent'],
    ['time budget', h.budget_ms + ' ms'],
    ['continuous', h.free_run_dhz ? (h.free_run_dhz / 10) + ' Hz' : 'off'],
    ['model mask', '0x' + h.model_mask.toString(16)],
    ['cameras', h.capture_mode + ': ' + h.camera.pairs_delivered + ' pairs, ' + h.camera.timeouts +
        ' timeouts, ' + h.camera.unpaired_drops + ' unpaired, ' + h.camera.errors + ' errors'],
    ['CAN', h.can.state + ': ' + h.can.tx_frames + ' sent, ' + h.can.rx_frames + ' received, ' +
        h.can.tx_dropped + ' send drops, ' + h.can.rx_dropped + ' receive drops, ' +
        h.can.bus_off_events + ' bus-off'],
    ['triggers', h.counters.triggers_accepted + ' accepted, ' + h.counters.triggers_rejected +
        ' rejected, ' + h.counters.triggers_dropped + ' dropped; ' + h.counters.result_sets +
        ' result sets'],
    ['recording', h.recording.on ? h.recording.written + ' written, ' + h.recording.pending +
        ' pending, ' + h.recording.dropped + ' dropped' : 'off (record_dir)'],
  ];
  const body = $('health-table');
  body.replaceChildren(...rows.map((r) => row(r)));
  const emcy = $('emcy');
  emcy.replaceChildren();
  for (const e of h.emcy_history) {
    const li = document.createElement('li');
    li.textContent = '0x' + e.code.toString(16).padStart(4, '0') + ' ' + e.text + ' (detail 0x' +
                     e.detail.toString(16) + ')';
    emcy.appendChild(li);
  }
}

function showAccess(access) {
  page.loginPossible = access.login_possible;
  page.loggedIn = access.logged_in;
  if (access.logged_in) page.csrf = access.csrf;
  $('login-form').hidden = access.logged_in || !access.login_possible;
  $('logout').hidden = !access.logged_in;
  $('access').textContent = !access.login_possible ? 'read-only: no password configured'
                          : access.logged_in ? 'logged in' : 'read-only until you log in';
  for (const b of document.querySelectorAll('.needs-login')) b.disabled = !access.logged_in;
}

async function poll() {
  try {
    const response = await fetch('/api/status', { credentials: 'same-origin' });
    if (response.ok) {
      const status = await response.json();
      page.status = status;
      $('show-volume').disabled = !status.volume;
      $('show-table').disabled = !status.table_plane;
      showAccess(status.access);
      showHealth(status.health);
      showResults(status.result);
      await refreshLive(status.result);
    }
  } catch (e) {
    say('message', 'the sensor does not answer', false);
  }
  setTimeout(poll, 500);
}

async function loadRecordings() {
  const list = $('recordings');
  const response = await fetch('/api/recordings', { credentials: 'same-origin' });
  if (!response.ok) {
    list.replaceChildren();
    return;
  }
  const names = await response.json();
  list.replaceChildren(...names.slice().reverse().map((n) => {
    const li = document.createElement('li');
    const a = document.createElement('a');
    a.href = '/api/recordings?pair=' + n;
    a.textContent = n + '.tar';
    a.download = n + '.tar';
    li.appendChild(a);
    return li;
  }));
}

async function loadCalibrationPairs() {
  const list = $('calibration-pairs');
  const response = await fetch('/api/calibration', { credentials: 'same-origin' });
  if (!response.ok) {
    list.replaceChildren();
    return;
  }
  const answer = await response.json();
  list.replaceChildren(...answer.pairs.slice().reverse().map((n) => {
    const li = document.createElement('li');
    const a = document.createElement('a');
    a.href = '/api/calibration?pair=' + n;
    a.textContent = 'calibration-' + n + '.tar';
    a.download = 'calibration-' + n + '.tar';
    li.appendChild(a);
    return li;
  }));
}

function settingInput(key) {
  const input = document.createElement('input');
  input.value = key.value;
  input.dataset.key = key.name;
  input.dataset.original = key.value;
  input.disabled = key.locked;
  input.title = key.locked ? 'changed in the configuration file only' : key.type;
  input.addEventListener('input', () => input.classList.toggle('changed',
                                                               input.value !== input.dataset.original));
  return input;
}

async function loadSettings() {
  const response = await fetch('/api/settings', { credentials: 'same-origin' });
  const settings = await response.json();
  $('settings-file').textContent = settings.file ? 'configuration file: ' + settings.file
                                                 : 'started without a configuration file';
  const body = $('settings-table');
  body.replaceChildren();
  for (const key of settings.keys) {
    const tr = document.createElement('tr');
    const name = document.createElement('td');
    name.textContent = key.name + (key.runtime ? ' *' : '');
    name.title = key.runtime ? 'applies at once' : 'applies at the next start';
    const value = document.createElement('td');
    value.appendChild(settingInput(key));
    const type = document.createElement('td');
    type.textContent = key.type;
    const help = document.createElement('td');
    help.textContent = key.help;
    help.className = 'help';
    tr.append(name, value, type, help);
    body.appendChild(tr);
  }
}

async function applySettings() {
  const lines = [];
  for (const input of document.querySelectorAll('#settings-table input.changed')) {
    lines.push(input.dataset.key + ' = ' + input.value);
  }
  if (lines.length === 0) {
    say('settings-message', 'nothing changed', true);
    return;
  }
  const answer = await post('/api/settings', lines.join('\n') + '\n');
  say('settings-message', answer.message, answer.ok);
  if (answer.ok) await loadSettings();
}

async function login(event) {
  event.preventDefault();
  const response = await fetch('/api/login', { method: 'POST', body: $('password').value,
                                               credentials: 'same-origin' });
  const answer = await response.json();
  $('password').value = '';
  if (answer.ok) {
    page.csrf = answer.csrf;
    showAccess({ login_possible: true, logged_in: true, csrf: answer.csrf });
    say('message', 'logged in', true);
  } else {
    say('message', answer.message, false);
  }
}

function wire() {
  $('login-form').addEventListener('submit', login);
  $('logout').addEventListener('click', async () => {
    await action('/api/logout');
    page.csrf = '';
  });
  $('trigger').addEventListener('click', () => action('/api/trigger'));
  $('continuous-start').addEventListener('click',
      () => action('/api/continuous?rate_dhz=' + encodeURIComponent($('rate').value)));
  $('continuous-stop').addEventListener('click', () => action('/api/continuous?rate_dhz=0'));
  $('record').addEventListener('click',
      () => action('/api/record?pairs=' + encodeURIComponent($('record-pairs').value)));
  $('clear-fault').addEventListener('click', () => action('/api/clear-fault'));
  $('capture-pair').addEventListener('click', async () => {
    await action('/api/calibration/capture');
    loadCalibrationPairs();
  });
  $('settings-apply').addEventListener('click', applySettings);
  $('settings-save').addEventListener('click', async () => {
    const answer = await post('/api/settings/save');
    say('settings-message', answer.message, answer.ok);
  });
  $('sides').addEventListener('change', () => { page.shownResult = -1; });
  $('show-volume').addEventListener('change', () => { page.shownResult = -1; });
  $('show-table').addEventListener('change', () => { page.shownResult = -1; });
  for (const b of document.querySelectorAll('.needs-login')) b.disabled = true;
}

wire();
poll();
loadSettings();
loadRecordings();
loadCalibrationPairs();
setInterval(loadRecordings, 3000);
setInterval(loadCalibrationPairs, 3000);
