// Write or force one value: an input that fits the type (TRUE/FALSE buttons
// for BOOL, a number field with its range and unit, a duration for TIME), an
// element chooser for arrays, and for a force a confirmation in words.
import { useState } from 'preact/hooks';
import { force, writeTag } from '../api/endpoints.js';
import { arrayBounds, elementType, formatValue } from '../lib/format.js';
import { intRange, isIntegerType, isRealType, parseInput } from '../lib/iec.js';
import { ErrorNote, Modal } from './common.jsx';
import { hasValue, valueOf } from '../live/hub.js';
import { useLive } from '../live/hooks.js';

export function ValueInput({ type, unit, value, onInput, id }) {
  if (type === 'BOOL') {
    return (
      <div class="segmented" role="radiogroup" aria-label="new value">
        {['TRUE', 'FALSE'].map((v) => (
          <label class={value === v ? 'on' : ''}>
            <input type="radio" name={id} value={v} checked={value === v} onChange={() => onInput(v)} /> {v}
          </label>
        ))}
      </div>
    );
  }
  const range = intRange(type);
  const placeholder = isIntegerType(type) ? `whole number${range ? `, ${range.min} to ${range.max}` : ''}`
    : isRealType(type) ? 'number, e.g. 1.5' : type === 'TIME' || type === 'LTIME' ? 'duration, e.g. 250ms or T#1.5s' : 'text';
  return (
    <div class="with-unit">
      <input id={id} name="value" value={value} placeholder={placeholder} autocomplete="off"
        inputMode={isIntegerType(type) ? 'numeric' : isRealType(type) ? 'decimal' : 'text'}
        onInput={(e) => onInput(e.currentTarget.value)} />
      {unit ? <span class="unit">{unit}</span> : null}
    </div>
  );
}

// target: {name (tag or instance.pin), type, unit, current, access}
export function ChangeDialog({ mode, target, onClose, onDone }) {
  const bounds = target ? arrayBounds(target.type) : null;
  const [element, setElement] = useState(bounds ? String(bounds.lower) : '');
  const [text, setText] = useState('');
  const [confirmed, setConfirmed] = useState(false);
  const [error, setError] = useState(null);
  const [busy, setBusy] = useState(false);
  useLive(target ? [target.name] : [], 250); // "Now:" follows the PLC while the dialog is open
  if (!target) return null;
  const live = hasValue(target.name) ? valueOf(target.name) : target.current;
  const type = elementType(target.type);
  const ref = bounds ? `${target.name}[${element}]` : target.name;
  const parsed = text === '' ? null : parseInput(text, type);
  const elementOk = !bounds || (/^-?\d+$/.test(element) && Number(element) >= bounds.lower && Number(element) <= bounds.upper);
  const ready = parsed && parsed.ok && elementOk && (mode !== 'force' || confirmed);
  const currentValue = bounds && Array.isArray(live) && elementOk ? live[Number(element) - bounds.lower] : live;

  async function submit(e) {
    e.preventDefault();
    if (!ready) return;
    setBusy(true);
    setError(null);
    try {
      if (mode === 'force') await force(ref, parsed.value);
      else if (bounds) await writeTag(ref, parsed.value);
      else await writeTag(target.name, parsed.value);
      onDone(ref);
    } catch (err) {
      setError(err);
    } finally {
      setBusy(false);
    }
  }

  const title = mode === 'force' ? `Force ${target.name}` : `Write ${target.name}`;
  return (
    <Modal open title={title} onClose={onClose}>
      <form class="form" onSubmit={submit}>
        <p class="sub">{target.type}{target.unit ? `, in ${target.unit}` : ''}. Now: <strong>{formatValue(currentValue, type)}</strong>{target.unit ? ` ${target.unit}` : ''}</p>
        {bounds ? (
          <label>Element ({bounds.lower} to {bounds.upper})
            <input name="element" inputMode="numeric" value={element} onInput={(e) => setElement(e.currentTarget.value)} />
          </label>
        ) : null}
        <label>New value
          <ValueInput id="change-value" type={type} unit={target.unit} value={text} onInput={setText} />
        </label>
        {parsed && !parsed.ok ? <p class="error-note">{parsed.error}</p> : null}
        {!elementOk ? <p class="error-note">Choose an element from {bounds.lower} to {bounds.upper}.</p> : null}
        {mode === 'force' ? (
          <label class="confirm">
            <input type="checkbox" name="confirm" checked={confirmed} onChange={(e) => setConfirmed(e.currentTarget.checked)} />
            <span>I understand that <strong>{ref}</strong> will be held at this value whatever the program or a driver writes, until someone unforces it.</span>
          </label>
        ) : (
          <p class="hint">The value is applied at the start of the owning task's next scan. The program may write it again afterwards.</p>
        )}
        <ErrorNote error={error} />
        <div class="actions">
          <button type="button" class="btn" onClick={onClose}>Cancel</button>
          <button type="submit" class={mode === 'force' ? 'btn danger' : 'btn primary'} disabled={!ready || busy}>
            {mode === 'force' ? 'Force' : 'Write'}
          </button>
        </div>
      </form>
    </Modal>
  );
}
