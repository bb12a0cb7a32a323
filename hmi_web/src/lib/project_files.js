// A project chosen in the browser: its files as text, named relative to the
// folder holding them all (as the store names a version's files), and which
// one is the main file. Pure (test/project_files.test.mjs).

// files: [{path, text}] with '/'-separated paths ('proj/sync.yaml' from a
// folder pick, or 'sync.yaml'). Strips the common leading folders.
export function relativeNames(files) {
  const parts = files.map((f) => f.path.split('/').filter(Boolean));
  let common = 0;
  if (parts.length) {
    const first = parts[0];
    outer: for (; common < first.length - 1; common++) {
      for (const p of parts) if (p.length - 1 <= common || p[common] !== first[common]) break outer;
    }
  }
  return files.map((f, i) => ({ name: parts[i].slice(common).join('/'), text: f.text }));
}

// The main file: the one no other file includes; among several, one with a
// project: section; else the first.
export function guessMain(files) {
  const yaml = files.filter((f) => /\.ya?ml$/i.test(f.name));
  const included = new Set();
  for (const f of yaml) {
    const m = /^include:\s*(.*)$/m.exec(f.text);
    if (!m) continue;
    let list = m[1].trim();
    const block = [];
    if (!list) {
      const after = f.text.slice(m.index + m[0].length).split('\n');
      for (const line of after) { const b = /^\s*-\s*(.+)$/.exec(line); if (b) block.push(b[1]); else if (line.trim()) break; }
    }
    const names = block.length ? block : list.replace(/^\[|\]$/g, '').split(',');
    for (const n of names) included.add(n.trim().replace(/^['"]|['"]$/g, ''));
  }
  const roots = yaml.filter((f) => !included.has(f.name) && ![...included].some((i) => f.name.endsWith(`/${i}`)));
  const withProject = roots.find((f) => /^project:/m.test(f.text));
  return (withProject || roots[0] || yaml[0] || files[0] || { name: '' }).name;
}

export function projectBody(files, main) {
  return { main, files: Object.fromEntries(files.map((f) => [f.name, f.text])) };
}

// The errors of one file, by line: Map line → [messages].
export function errorsByLine(errors, file) {
  const out = new Map();
  for (const e of errors) {
    if (!e.where || !sameFile(e.where.file, file)) continue;
    if (!out.has(e.where.line)) out.set(e.where.line, []);
    out.get(e.where.line).push(e);
  }
  return out;
}

// The server may name a file by a longer path than the upload's name.
export function sameFile(a, b) {
  if (!a || !b) return false;
  return a === b || a.endsWith(`/${b}`) || b.endsWith(`/${a}`);
}
