// Tags & pins: every tag with its live value, a filter, write (operator) and
// force/unforce (engineer) from the row; block instances open to their pins,
// ST instances also to their variables.
import { useEffect, useState } from 'preact/hooks';
import { getBlocks, getTags, unforce } from '../api/endpoints.js';
import { can, hint } from '../auth/session.js';
import { hasValue, isForced, qualityOf, refError, valueOf } from '../live/hub.js';
import { useLive } from '../live/hooks.js';
import { formatValue } from '../lib/format.js';
import { ACCESS_WORDS, tagMatches } from '../lib/tag_filter.js';
import { ErrorNote, Value } from '../components/common.jsx';
import { ChangeDialog } from '../components/change_dialog.jsx';

const MAX_LIVE = 1000; // refs streamed at once from this page (one subscription takes up to 4096)

const anyForced = (f) => (Array.isArray(f) ? f.some(Boolean) : !!f);


function liveForced(ref, fallback) {
  return hasValue(ref) ? isForced(ref) || anyForced(fallback) : anyForced(fallback);
}

function RowActions({ session, item, writable, onChange, onUnforce }) {
  const forced = liveForced(item.name, item.forced);
  const canWrite = can('write', session);
  const writeHint = !canWrite ? hint('write')
    : !writable ? (item.writtenEveryScan ? 'The program writes this value every scan, so a write would not hold. An engineer can force it.'
      : 'The project does not allow writing this value from outside (hmi: read). An engineer can force it.') : '';
  return (
    <div class="row-actions">
      <button type="button" class="btn small" disabled={!canWrite || !writable} title={writeHint}
        onClick={() => onChange('write', item)}>Write…</button>
      {forced ? (
        <button type="button" class="btn small danger" disabled={!can('force', session)} title={can('force', session) ? 'Release the forced value' : hint('force')}
          onClick={() => onUnforce(item)}>Unforce</button>
      ) : (
        <button type="button" class="btn small" disabled={!can('force', session)} title={can('force', session) ? '' : hint('force')}
          onClick={() => onChange('force', item)}>Force…</button>
      )}
    </div>
  );
}

// A variable of an ST instance (block.variables): an engineer writes it
// once (the program goes on from it) or forces it.
function VariableRow({ block, v, session, onChange, onUnforce }) {
  const ref = `${block.name}.${v.name}`;
  const engineer = can('force', session);
  const item = { name: ref, type: v.type, unit: '', forced: v.forced, access: 'readwrite', current: hasValue(ref) ? valueOf(ref) : v.value };
  const forced = liveForced(ref, v.forced);
  return (
    <tr class="variable-row" data-ref={ref}>
      <td data-label="Variable" class="pin-name">· {ref}</td>
      <td data-label="Type">{v.type}</td>
      <td data-label="Direction">variable</td>
      <td data-label="Value" class="value-cell"><Value value={item.current} type={v.type} forced={forced} quality={qualityOf(ref)} /></td>
      <td data-label="" colSpan={2}>
        <div class="row-actions">
          <button type="button" class="btn small" disabled={!engineer}
            title={engineer ? 'Write once: the program goes on from this value' : 'Writing a variable of an ST program needs the engineer role'}
            onClick={() => onChange('write', item)}>Write…</button>
          <button type="button" class="btn small" disabled={!engineer} title={engineer ? '' : hint('force')}
            onClick={() => (forced ? onUnforce(item) : onChange('force', item))}>{forced ? 'Unforce' : 'Force…'}</button>
        </div>
      </td>
    </tr>
  );
}

function BlockRow({ block, open, onToggle, session, onChange, onUnforce }) {
  const variables = block.variables || [];
  // Streamed live: the first MAX_LIVE (an instance lists up to 1024 variables).
  const refs = open ? [...block.pins, ...variables].slice(0, MAX_LIVE).map((p) => `${block.name}.${p.name}`) : [];
  useLive(refs, 200);
  return (
    <>
      <tr class="block-row">
        <td data-label="Instance" colSpan={1}>
          <button type="button" class="disclosure" aria-expanded={open} onClick={onToggle}>
            {open ? '▾' : '▸'} <strong>{block.name}</strong>
          </button>
        </td>
        <td data-label="Type">{block.type}</td>
        <td data-label="Task">{block.task}{block.position !== null ? ` #${block.position}` : ''}</td>
        <td data-label="Pins" colSpan={3}>{block.pins.length} pins{variables.length ? `, ${variables.length} variables` : ''}</td>
      </tr>
      {open ? block.pins.map((p) => {
        const ref = `${block.name}.${p.name}`;
        const item = { name: ref, type: p.type, unit: p.unit, forced: p.forced, access: p.direction === 'in' ? 'readwrite' : 'read', current: hasValue(ref) ? valueOf(ref) : p.value };
        return (
          <tr class="pin-row" data-ref={ref}>
            <td data-label="Pin" class="pin-name">{p.direction === 'out' ? '→ ' : '← '}{ref}</td>
            <td data-label="Type">{p.type}</td>
            <td data-label="Direction">{p.direction === 'out' ? 'output' : 'input'}</td>
            <td data-label="Value" class="value-cell"><Value value={item.current} type={p.type} unit={p.unit} forced={liveForced(ref, p.forced)} quality={qualityOf(ref)} /></td>
            <td data-label="" colSpan={2}>
              <div class="row-actions">
                <button type="button" class="btn small" disabled={!can('force', session)} title={can('force', session) ? '' : hint('force')}
                  onClick={() => (liveForced(ref, p.forced) ? onUnforce(item) : onChange('force', item))}>
                  {liveForced(ref, p.forced) ? 'Unforce' : 'Force…'}
                </button>
              </div>
            </td>
          </tr>
        );
      }) : null}
      {open ? variables.map((v) => <VariableRow block={block} v={v} session={session} onChange={onChange} onUnforce={onUnforce} />) : null}
    </>
  );
}

export function TagsPage({ session }) {
  const [tags, setTags] = useState(null);
  const [blocks, setBlocks] = useState(null);
  const [error, setError] = useState(null);
  const [query, setQuery] = useState('');
  const [forcedOnly, setForcedOnly] = useState(location.hash.includes('forced'));
  const [openBlocks, setOpenBlocks] = useState(new Set());
  const [dialog, setDialog] = useState(null);
  const [notice, setNotice] = useState(null);

  async function reload() {
    if (document.hidden) return;
    try {
      const [t, b] = await Promise.all([getTags(), getBlocks().catch(() => [])]);
      setTags(t);
      setBlocks(b);
      setError(null);
    } catch (e) { setError(e); }
  }
  useEffect(() => { reload(); const id = setInterval(reload, 5000); return () => clearInterval(id); }, []);

  // Recomputed at every live update: the filter also matches values.
  const shown = (tags || []).filter((t) => tagMatches(t, query, hasValue(t.name) ? formatValue(valueOf(t.name), t.type) : '')
    && (!forcedOnly || liveForced(t.name, t.forced)));
  const liveRefs = shown.slice(0, MAX_LIVE).map((t) => t.name);
  useLive(liveRefs, 150);
  const shownBlocks = (blocks || []).filter((b) => !query || [b.name, b.type, b.task].join(' ').toLowerCase().includes(query.toLowerCase())
    || [...b.pins, ...(b.variables || [])].some((p) => `${b.name}.${p.name}`.toLowerCase().includes(query.toLowerCase())));

  async function doUnforce(item) {
    setNotice(null);
    try {
      await unforce(item.name);
      setNotice(`${item.name} is no longer forced.`);
      reload();
    } catch (e) { setNotice(null); setError(e); }
  }

  const toggle = (name) => {
    const s = new Set(openBlocks);
    if (s.has(name)) s.delete(name); else s.add(name);
    setOpenBlocks(s);
  };

  return (
    <>
      <h1>Tags &amp; pins</h1>
      <div class="toolbar">
        <input type="search" class="filter" placeholder="Filter by name, type, value, unit, task or access" aria-label="Filter"
          value={query} onInput={(e) => setQuery(e.currentTarget.value)} />
        <label class="check"><input type="checkbox" checked={forcedOnly} onChange={(e) => setForcedOnly(e.currentTarget.checked)} /> forced only</label>
      </div>
      {!session ? <p class="hint">Log in as an operator to write values, as an engineer to force them.</p> : null}
      <ErrorNote error={error} />
      {notice ? <p class="ok-note" role="status">{notice}</p> : null}
      {tags === null && !error ? <p class="hint">Reading the tags…</p> : null}
      {tags ? (
        <div class="table-wrap">
          <table class="data cards" id="tags-table">
            <thead><tr><th>Tag</th><th>Type</th><th>Task</th><th>Value</th><th>Access</th><th>Actions</th></tr></thead>
            <tbody>
              {shown.map((t) => {
                const current = hasValue(t.name) ? valueOf(t.name) : undefined;
                return (
                  <tr data-tag={t.name} class={liveForced(t.name, t.forced) ? 'forced-row' : ''}>
                    <td data-label="Tag"><div><strong>{t.name}</strong>{t.description ? <div class="sub">{t.description}</div> : null}</div></td>
                    <td data-label="Type"><span>{t.type}{t.retain ? <span class="pill">retain</span> : null}</span></td>
                    <td data-label="Task">{t.task}</td>
                    <td data-label="Value" class="value-cell"><Value value={current} type={t.type} unit={t.unit}
                      forced={Array.isArray(t.forced) && liveForced(t.name, t.forced) ? t.forced : liveForced(t.name, t.forced)}
                      quality={qualityOf(t.name)} />{refError(t.name) ? <div class="sub">{refError(t.name)}</div> : null}</td>
                    <td data-label="Access">{ACCESS_WORDS[t.access] || t.access}</td>
                    <td data-label="">
                      <RowActions session={session} item={{ ...t, current }} writable={t.writable}
                        onChange={(mode, item) => setDialog({ mode, target: item })} onUnforce={doUnforce} />
                    </td>
                  </tr>
                );
              })}
            </tbody>
          </table>
          {shown.length === 0 ? <p class="hint">No tag matches “{query}”.</p> : null}
          {shown.length > MAX_LIVE ? <p class="hint">Live values for the first {MAX_LIVE} tags; narrow the filter to see the others move.</p> : null}
        </div>
      ) : null}
      {blocks && blocks.length ? (
        <>
          <h2>Block instances</h2>
          <div class="table-wrap">
            <table class="data cards" id="blocks-table">
              <thead><tr><th>Instance / pin</th><th>Type</th><th>Task</th><th>Value</th><th colSpan={2}>Actions</th></tr></thead>
              <tbody>
                {shownBlocks.map((b) => (
                  <BlockRow block={b} open={openBlocks.has(b.name)} onToggle={() => toggle(b.name)} session={session}
                    onChange={(mode, item) => setDialog({ mode, target: item })} onUnforce={doUnforce} />
                ))}
              </tbody>
            </table>
          </div>
        </>
      ) : null}
      {dialog ? (
        <ChangeDialog mode={dialog.mode} target={dialog.target} onClose={() => setDialog(null)}
          onDone={(ref) => { setDialog(null); setNotice(dialog.mode === 'force' ? `${ref} is forced.` : `Written to ${ref}.`); reload(); }} />
      ) : null}
    </>
  );
}
