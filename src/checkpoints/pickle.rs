//! A pickle reader that runs nothing: the subset of pickle's machine `torch.save` uses to
//! write a state dict (protocol 2, and protocol 4's framing), with a fixed list of globals.
//!
//! A pickle is a program: unpickled by Python, a `GLOBAL` names any callable and `REDUCE`
//! calls it. Here a `GLOBAL` outside [`Global`]'s list is refused at once, naming it, and
//! the allowed ones are interpreted, not called: an ordered dict becomes a dict, a tensor
//! rebuild becomes a [`TensorRef`] to a storage of the archive. Values are shared (`Rc`)
//! rather than copied when a memo entry is fetched, so a small pickle cannot grow
//! exponentially by fetching a container into itself (candle's reader clones them), and
//! nesting is bounded so that dropping a value cannot overflow the stack.
//!
//! Sharing makes a bound on nesting subtle: a list memoised, fetched and then grown would
//! leave every earlier copy of its depth stale. So a list or dict is *sealed* once it is
//! put inside another container (as `pickle.dump` writes them: filled, then used), a sealed
//! one cannot grow, and a container keeps its depth itself, where every alias sees it.
//! With no container growing after it is nested, no cycle can be made and every depth is
//! exact.

use std::cell::RefCell;
use std::rc::Rc;

/// How deeply containers may nest: a state dict is a dict of tensors of tuples (depth 4).
const MAX_DEPTH: usize = 64;

/// The globals a state dict's pickle names; anything else is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Global {
    /// `collections.OrderedDict`: read as a dict (its order kept).
    OrderedDict,
    /// `torch._utils._rebuild_tensor_v2`: a tensor over a storage.
    RebuildTensor,
    /// `torch._utils._rebuild_parameter`: an `nn.Parameter` around a tensor.
    RebuildParameter,
    /// `torch.<Kind>Storage`: the element type of a storage.
    Storage(StorageKind),
}

/// The element type of a torch storage (`torch.FloatStorage` is `f32`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StorageKind {
    F32,
    /// Any other type: named so the refusal can say which.
    Other(&'static str),
}

impl Global {
    fn named(module: &str, name: &str) -> Option<Self> {
        const OTHER_STORAGES: [&str; 10] = [
            "DoubleStorage",
            "HalfStorage",
            "BFloat16Storage",
            "LongStorage",
            "IntStorage",
            "ShortStorage",
            "CharStorage",
            "ByteStorage",
            "BoolStorage",
            "ComplexFloatStorage",
        ];
        match (module, name) {
            ("collections", "OrderedDict") => Some(Self::OrderedDict),
            ("torch._utils", "_rebuild_tensor_v2") => Some(Self::RebuildTensor),
            ("torch._utils", "_rebuild_parameter") => Some(Self::RebuildParameter),
            ("torch", "FloatStorage") => Some(Self::Storage(StorageKind::F32)),
            ("torch", other) => OTHER_STORAGES
                .iter()
                .find(|s| **s == other)
                .map(|s| Self::Storage(StorageKind::Other(s))),
            _ => None,
        }
    }
}

/// A storage of the archive: `data/<key>` holding `numel` elements.
#[derive(Debug, Clone, PartialEq)]
pub struct StorageRef {
    pub kind: StorageKind,
    pub key: String,
    pub numel: usize,
}

/// A tensor: a strided view of a storage.
#[derive(Debug, Clone, PartialEq)]
pub struct TensorRef {
    pub storage: StorageRef,
    pub offset: usize,
    pub shape: Vec<usize>,
    pub stride: Vec<usize>,
}

/// A value of the pickle machine.
#[derive(Debug, Clone)]
pub enum Value {
    None,
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(Rc<str>),
    Tuple(Rc<Vec<Value>>),
    List(Shared<Vec<Value>>),
    Dict(Shared<Vec<(Value, Value)>>),
    Global(Global),
    Storage(Rc<StorageRef>),
    Tensor(Rc<TensorRef>),
    /// The stack's marker for `TUPLE`, `APPENDS`, `SETITEMS`.
    Mark,
}

/// A list or dict as the memo shares it: every alias sees it grow.
pub type Shared<T> = Rc<RefCell<Container<T>>>;

/// A list's or dict's items, with what the machine keeps of it: how deeply it nests, and
/// whether it sits inside another container already (then it may not grow).
#[derive(Debug, Default)]
pub struct Container<T> {
    pub items: T,
    depth: usize,
    sealed: bool,
}

impl Value {
    /// How deeply the value nests: a container's own depth, which its aliases share; a
    /// tuple's, which never changes, is kept beside it on the stack (`recorded`).
    fn depth(&self, recorded: usize) -> usize {
        match self {
            Value::List(list) => list.borrow().depth,
            Value::Dict(dict) => dict.borrow().depth,
            _ => recorded,
        }
    }

    /// Marks a list or dict as put inside another container.
    fn seal(&self) {
        match self {
            Value::List(list) => list.borrow_mut().sealed = true,
            Value::Dict(dict) => dict.borrow_mut().sealed = true,
            _ => {}
        }
    }

    fn kind(&self) -> &'static str {
        match self {
            Value::None => "None",
            Value::Bool(_) => "a bool",
            Value::Int(_) => "an int",
            Value::Float(_) => "a float",
            Value::Str(_) => "a str",
            Value::Tuple(_) => "a tuple",
            Value::List(_) => "a list",
            Value::Dict(_) => "a dict",
            Value::Global(_) => "a global",
            Value::Storage(_) => "a storage",
            Value::Tensor(_) => "a tensor",
            Value::Mark => "a mark",
        }
    }

    fn usize(&self, what: &str) -> Result<usize, String> {
        match self {
            Value::Int(i) => usize::try_from(*i).map_err(|_| format!("{what} is {i}")),
            other => Err(format!("{what} is {}, expected an int", other.kind())),
        }
    }

    fn usizes(&self, what: &str) -> Result<Vec<usize>, String> {
        match self {
            Value::Tuple(items) => items.iter().map(|v| v.usize(what)).collect(),
            other => Err(format!("{what} is {}, expected a tuple", other.kind())),
        }
    }
}

/// The top-level object of the pickle `bytes`: a dict for a state dict. Refuses, naming it,
/// every opcode and global a state dict does not use.
pub fn read(bytes: &[u8]) -> Result<Value, String> {
    Machine::default().run(bytes)
}

#[derive(Default)]
struct Machine {
    stack: Vec<(Value, usize)>,
    memo: std::collections::HashMap<u32, (Value, usize)>,
}

impl Machine {
    fn run(mut self, bytes: &[u8]) -> Result<Value, String> {
        let mut at = 0usize;
        let take = |n: usize, at: &mut usize| -> Result<&[u8], String> {
            let end = at.checked_add(n).filter(|e| *e <= bytes.len());
            let Some(end) = end else {
                return Err(format!(
                    "the pickle ends inside an instruction at byte {at}"
                ));
            };
            let s = &bytes[*at..end];
            *at = end;
            Ok(s)
        };
        loop {
            let position = at;
            let op = take(1, &mut at)?[0];
            let fail = |message: String| format!("byte {position} (opcode 0x{op:02x}): {message}");
            match op {
                0x80 => {
                    take(1, &mut at)?; // PROTO n
                }
                0x95 => {
                    take(8, &mut at)?; // FRAME length: frames are only a read-ahead hint
                }
                b'.' => {
                    // STOP
                    let (value, _) = self.pop().map_err(fail)?;
                    return Ok(value);
                }
                b'c' => {
                    // GLOBAL module\nname\n
                    let module = line(bytes, &mut at).map_err(fail)?;
                    let name = line(bytes, &mut at).map_err(fail)?;
                    let global = Global::named(&module, &name).ok_or_else(|| {
                        format!(
                            "the pickle names the global `{module}.{name}`, which is not part of a \
                             state dict of tensors (only collections.OrderedDict, torch's tensor \
                             rebuilds and storages are); nothing in the file was run"
                        )
                    })?;
                    self.push(Value::Global(global), 0).map_err(fail)?;
                }
                b'(' => self.push(Value::Mark, 0).map_err(fail)?,
                b'N' => self.push(Value::None, 0).map_err(fail)?,
                0x88 => self.push(Value::Bool(true), 0).map_err(fail)?,
                0x89 => self.push(Value::Bool(false), 0).map_err(fail)?,
                b'K' => {
                    let v = take(1, &mut at)?[0];
                    self.push(Value::Int(i64::from(v)), 0).map_err(fail)?;
                }
                b'M' => {
                    let v = u16::from_le_bytes(fixed(take(2, &mut at)?)?);
                    self.push(Value::Int(i64::from(v)), 0).map_err(fail)?;
                }
                b'J' => {
                    let v = i32::from_le_bytes(fixed(take(4, &mut at)?)?);
                    self.push(Value::Int(i64::from(v)), 0).map_err(fail)?;
                }
                0x8a => {
                    // LONG1 n bytes, two's complement little-endian
                    let n = usize::from(take(1, &mut at)?[0]);
                    let digits = take(n, &mut at)?;
                    if n > 8 {
                        return Err(fail(format!("an integer of {n} bytes")));
                    }
                    let mut buf = if digits.last().is_some_and(|b| b & 0x80 != 0) {
                        [0xff; 8]
                    } else {
                        [0; 8]
                    };
                    buf[..n].copy_from_slice(digits);
                    self.push(Value::Int(i64::from_le_bytes(buf)), 0)
                        .map_err(fail)?;
                }
                b'G' => {
                    let v = f64::from_be_bytes(fixed(take(8, &mut at)?)?);
                    self.push(Value::Float(v), 0).map_err(fail)?;
                }
                b'X' | 0x8c | b'U' | b'T' => {
                    // BINUNICODE (u32), SHORT_BINUNICODE (u8), SHORT_BINSTRING, BINSTRING
                    let n = if matches!(op, b'X' | b'T') {
                        u32::from_le_bytes(fixed(take(4, &mut at)?)?) as usize
                    } else {
                        usize::from(take(1, &mut at)?[0])
                    };
                    let text = std::str::from_utf8(take(n, &mut at)?)
                        .map_err(|_| fail("a string that is not UTF-8".into()))?;
                    self.push(Value::Str(Rc::from(text)), 0).map_err(fail)?;
                }
                b')' => self
                    .push(Value::Tuple(Rc::new(Vec::new())), 1)
                    .map_err(fail)?,
                b']' => self.push(Value::List(Rc::default()), 1).map_err(fail)?,
                b'}' => self.push(Value::Dict(Rc::default()), 1).map_err(fail)?,
                0x85..=0x87 => {
                    let n = usize::from(op - 0x84);
                    let items = self.pop_n(n).map_err(fail)?;
                    self.push_tuple(items).map_err(fail)?;
                }
                b't' => {
                    let items = self.pop_to_mark().map_err(fail)?;
                    self.push_tuple(items).map_err(fail)?;
                }
                b'q' => {
                    let id = u32::from(take(1, &mut at)?[0]);
                    self.memo_put(id).map_err(fail)?;
                }
                b'r' => {
                    let id = u32::from_le_bytes(fixed(take(4, &mut at)?)?);
                    self.memo_put(id).map_err(fail)?;
                }
                0x94 => {
                    let id = self.memo.len() as u32; // MEMOIZE
                    self.memo_put(id).map_err(fail)?;
                }
                b'h' | b'j' => {
                    let id = if op == b'h' {
                        u32::from(take(1, &mut at)?[0])
                    } else {
                        u32::from_le_bytes(fixed(take(4, &mut at)?)?)
                    };
                    let entry = self
                        .memo
                        .get(&id)
                        .cloned()
                        .ok_or_else(|| fail(format!("memo {id} was never stored")))?;
                    self.stack.push(entry);
                }
                b'a' => {
                    let item = self.pop().map_err(fail)?;
                    self.extend_list(vec![item]).map_err(fail)?;
                }
                b'e' => {
                    let items = self.pop_to_mark().map_err(fail)?;
                    self.extend_list(items).map_err(fail)?;
                }
                b's' => {
                    let items = self.pop_n(2).map_err(fail)?;
                    self.extend_dict(items).map_err(fail)?;
                }
                b'u' => {
                    let items = self.pop_to_mark().map_err(fail)?;
                    self.extend_dict(items).map_err(fail)?;
                }
                b'Q' => {
                    // BINPERSID: torch's reference to a storage of the archive
                    let (id, _) = self.pop().map_err(fail)?;
                    let storage = storage(&id).map_err(fail)?;
                    self.push(Value::Storage(Rc::new(storage)), 1)
                        .map_err(fail)?;
                }
                b'R' => {
                    let (args, depth) = self.pop().map_err(fail)?;
                    let (callable, _) = self.pop().map_err(fail)?;
                    let value = reduce(&callable, &args).map_err(fail)?;
                    self.push(value, depth).map_err(fail)?;
                }
                b'b' => {
                    // BUILD: an ordered dict's attributes (a state dict's `_metadata`: the
                    // modules' versions) carry nothing the weights need.
                    let (state, _) = self.pop().map_err(fail)?;
                    match self.stack.last() {
                        Some((Value::Dict(_), _)) => {}
                        Some((other, _)) => {
                            return Err(fail(format!(
                                "BUILD on {} with {}: only a dict's attributes are read",
                                other.kind(),
                                state.kind()
                            )))
                        }
                        None => return Err(fail("BUILD on an empty stack".into())),
                    }
                }
                other => {
                    return Err(format!(
                        "byte {position}: opcode 0x{other:02x} is not one torch.save writes \
                         for a state dict"
                    ))
                }
            }
        }
    }

    fn push(&mut self, value: Value, depth: usize) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err(format!("containers nested more than {MAX_DEPTH} deep"));
        }
        self.stack.push((value, depth));
        Ok(())
    }

    fn pop(&mut self) -> Result<(Value, usize), String> {
        match self.stack.pop() {
            Some((Value::Mark, _)) => Err("a mark where a value was expected".into()),
            Some(entry) => Ok(entry),
            None => Err("the stack is empty".into()),
        }
    }

    fn pop_n(&mut self, n: usize) -> Result<Vec<(Value, usize)>, String> {
        let mut items: Vec<_> = (0..n).map(|_| self.pop()).collect::<Result<_, _>>()?;
        items.reverse();
        Ok(items)
    }

    fn pop_to_mark(&mut self) -> Result<Vec<(Value, usize)>, String> {
        let mark = self
            .stack
            .iter()
            .rposition(|(v, _)| matches!(v, Value::Mark))
            .ok_or("no mark on the stack")?;
        let items = self.stack.split_off(mark + 1);
        self.stack.pop();
        Ok(items)
    }

    fn push_tuple(&mut self, items: Vec<(Value, usize)>) -> Result<(), String> {
        let depth = 1 + nested(&items)?;
        let values = items.into_iter().map(|(v, _)| v).collect();
        self.push(Value::Tuple(Rc::new(values)), depth)
    }

    fn extend_list(&mut self, items: Vec<(Value, usize)>) -> Result<(), String> {
        let depth = 1 + nested(&items)?;
        match self.stack.last() {
            Some((Value::List(list), _)) => {
                let mut list = list.borrow_mut();
                list.grow(depth)?;
                list.items.extend(items.into_iter().map(|(v, _)| v));
                Ok(())
            }
            Some((other, _)) => Err(format!("APPEND to {}", other.kind())),
            None => Err("the stack is empty".into()),
        }
    }

    fn extend_dict(&mut self, items: Vec<(Value, usize)>) -> Result<(), String> {
        if !items.len().is_multiple_of(2) {
            return Err("SETITEMS with a key and no value".into());
        }
        let depth = 1 + nested(&items)?;
        match self.stack.last() {
            Some((Value::Dict(dict), _)) => {
                let mut dict = dict.borrow_mut();
                dict.grow(depth)?;
                let mut items = items.into_iter().map(|(v, _)| v);
                while let (Some(k), Some(v)) = (items.next(), items.next()) {
                    dict.items.push((k, v));
                }
                Ok(())
            }
            Some((other, _)) => Err(format!("SETITEM on {}", other.kind())),
            None => Err("the stack is empty".into()),
        }
    }

    fn memo_put(&mut self, id: u32) -> Result<(), String> {
        let top = self
            .stack
            .last()
            .ok_or("MEMOIZE on an empty stack")?
            .clone();
        self.memo.insert(id, top);
        Ok(())
    }
}

/// The deepest of `items`, which are about to be put inside a container: each list or dict
/// among them is sealed first, so that one put inside itself is refused as sealed.
fn nested(items: &[(Value, usize)]) -> Result<usize, String> {
    items.iter().for_each(|(v, _)| v.seal());
    Ok(items.iter().map(|(v, d)| v.depth(*d)).max().unwrap_or(0))
}

impl<T> Container<T> {
    /// The container receives items that make it `needed` deep.
    fn grow(&mut self, needed: usize) -> Result<(), String> {
        if self.sealed {
            return Err(
                "a list or dict grown after it was put inside another container (pickle.dump \
             fills a container before using it): not a state dict"
                    .into(),
            );
        }
        self.depth = self.depth.max(needed);
        if self.depth > MAX_DEPTH {
            return Err(format!("containers nested more than {MAX_DEPTH} deep"));
        }
        Ok(())
    }
}

/// The `N` bytes `take(N)` returned, as an array.
fn fixed<const N: usize>(bytes: &[u8]) -> Result<[u8; N], String> {
    bytes
        .try_into()
        .map_err(|_| format!("expected {N} bytes, got {}", bytes.len()))
}

/// A `GLOBAL`'s line of text.
fn line(bytes: &[u8], at: &mut usize) -> Result<String, String> {
    let rest = &bytes[*at..];
    let end = rest
        .iter()
        .take(256)
        .position(|b| *b == b'\n')
        .ok_or("a global's name without its end of line")?;
    *at += end + 1;
    String::from_utf8(rest[..end].to_vec()).map_err(|_| "a global's name is not UTF-8".into())
}

/// torch's persistent id `("storage", torch.<Kind>Storage, key, location, numel)`.
fn storage(id: &Value) -> Result<StorageRef, String> {
    let Value::Tuple(parts) = id else {
        return Err(format!(
            "a persistent id is {}, expected a tuple",
            id.kind()
        ));
    };
    match parts.as_slice() {
        [Value::Str(tag), Value::Global(Global::Storage(kind)), Value::Str(key), Value::Str(_location), numel]
            if &**tag == "storage" =>
        {
            Ok(StorageRef {
                kind: *kind,
                key: key.to_string(),
                numel: numel.usize("a storage's size")?,
            })
        }
        _ => Err("a persistent id that is not torch's reference to a storage".into()),
    }
}

/// `REDUCE`: what calling an allowed global would give, without calling it.
fn reduce(callable: &Value, args: &Value) -> Result<Value, String> {
    let Value::Tuple(args) = args else {
        return Err(format!("REDUCE's arguments are {}", args.kind()));
    };
    match callable {
        Value::Global(Global::OrderedDict) => Ok(Value::Dict(Rc::default())),
        Value::Global(Global::RebuildParameter) => match args.first() {
            Some(tensor @ Value::Tensor(_)) => Ok(tensor.clone()),
            _ => Err("_rebuild_parameter of something that is not a tensor".into()),
        },
        Value::Global(Global::RebuildTensor) => {
            // (storage, storage_offset, size, stride, requires_grad, backward_hooks, ...)
            let [Value::Storage(storage), offset, size, stride, ..] = args.as_slice() else {
                return Err("_rebuild_tensor_v2 without a storage, offset, size and stride".into());
            };
            Ok(Value::Tensor(Rc::new(TensorRef {
                storage: (**storage).clone(),
                offset: offset.usize("a tensor's offset")?,
                shape: size.usizes("a tensor's size")?,
                stride: stride.usizes("a tensor's stride")?,
            })))
        }
        Value::Global(Global::Storage(_)) => Err("a storage called as a function".into()),
        other => Err(format!("REDUCE calls {}", other.kind())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `collections.OrderedDict()` with one key → a tensor of 2 f32 (protocol 2).
    fn state_dict_pickle() -> Vec<u8> {
        let mut p = vec![0x80, 2];
        p.extend(b"ccollections\nOrderedDict\nq\x00)Rq\x01");
        p.extend(b"X\x01\x00\x00\x00w");
        p.extend(b"ctorch._utils\n_rebuild_tensor_v2\nq\x02(");
        p.extend(b"(X\x07\x00\x00\x00storagectorch\nFloatStorage\nX\x01\x00\x00\x000X\x03\x00\x00\x00cpuK\x02tQ");
        p.extend(b"K\x00K\x02\x85K\x01\x85\x89ccollections\nOrderedDict\n)RtR");
        p.extend(b"s}X\x09\x00\x00\x00_metadatah\x01sb.");
        p
    }

    #[test]
    fn a_state_dict_reads_as_a_dict_of_tensor_references() {
        let Value::Dict(dict) = read(&state_dict_pickle()).unwrap() else {
            panic!("not a dict")
        };
        let dict = dict.borrow();
        assert_eq!(dict.items.len(), 1);
        let (Value::Str(key), Value::Tensor(t)) = &dict.items[0] else {
            panic!("{:?}", dict.items[0])
        };
        assert_eq!(&**key, "w");
        assert_eq!(
            **t,
            TensorRef {
                storage: StorageRef {
                    kind: StorageKind::F32,
                    key: "0".into(),
                    numel: 2
                },
                offset: 0,
                shape: vec![2],
                stride: vec![1],
            }
        );
    }

    #[test]
    fn an_unexpected_global_is_refused_by_name_before_anything_else() {
        let err = read(b"\x80\x02cposix\nsystem\nX\x02\x00\x00\x00lsR.").unwrap_err();
        assert!(err.contains("`posix.system`"), "{err}");
        let err = read(b"\x80\x02c__main__\nQNetwork\n)R.").unwrap_err();
        assert!(err.contains("`__main__.QNetwork`"), "{err}");
    }

    #[test]
    fn truncated_and_unknown_input_is_refused() {
        let whole = state_dict_pickle();
        for cut in [1, 5, 40, whole.len() - 1] {
            assert!(read(&whole[..cut]).is_err(), "cut at {cut}");
        }
        assert!(read(b"\x80\x02i\x00.").unwrap_err().contains("opcode 0x69"));
    }

    #[test]
    fn a_memo_fetched_into_itself_shares_instead_of_growing() {
        // [] memo0; then 70 times: fetch it twice, append both into a new list, memoise.
        let mut p = b"\x80\x02]q\x00".to_vec();
        for i in 0..70u8 {
            p.extend([b']', b'(', b'h', i, b'h', i, b'e', b'q', i + 1]);
        }
        p.push(b'.');
        // Nesting grows by one per round: refused past the bound, never exponential.
        let err = read(&p).unwrap_err();
        assert!(err.contains("nested more than"), "{err}");
    }

    /// Issue 34, item 5: `] q1 h0 a` repeated, 3.3 MB of it, overflowed the stack: each new
    /// list, memoised, received the one before it, fetched from the memo with the depth it
    /// had when stored. Now a list put into another is sealed, so the chain is refused at
    /// its second link, and memo depths cannot be stale.
    #[test]
    fn a_chain_through_the_memo_is_refused_however_long() {
        let mut p = b"\x80\x02]q\x00".to_vec();
        for _ in 0..400_000 {
            p.extend(b"]q\x01h\x00aq\x00");
        }
        p.push(b'.');
        let err = read(&p).unwrap_err();
        assert!(
            err.contains("nested more than") || err.contains("grown after"),
            "{err}"
        );
        // A container appended into itself, directly or through another, is refused too.
        let err = read(b"\x80\x02]q\x00h\x00a.").unwrap_err();
        assert!(err.contains("grown after"), "{err}");
        let err = read(b"\x80\x02]q\x00]q\x01h\x00ah\x00h\x01a.").unwrap_err();
        assert!(err.contains("grown after"), "{err}");
    }
}
