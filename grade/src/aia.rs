//! Action–Intent Alignment (specification §11.4): keyword vocabularies with negation handling.
//!
//! The intent is lower-cased and split into word tokens (letters, digits, apostrophes;
//! `’` counts as `'`). Punctuation `, . ; : ! ? ( )`, newlines and the configured
//! clause-break words end a clause. Vocabulary entries are phrases of words; a word
//! ending in `*` matches any token starting with it. Overlapping keyword matches keep the
//! longest (then the earliest). A keyword is *negated* when a negation cue ends at most
//! `negation_window` tokens before it in the same clause; negated keywords are ignored.
//! A cue that lies strictly inside a longer keyword phrase ("no action", "do not move")
//! is part of that phrase, not a cue; a word that is both a cue and a keyword ("avoid")
//! acts as a cue when it negates a following keyword ("avoid catching"), else as a
//! keyword ("avoid the lamp").
//!
//! Score: 1 if only the ground-truth action's vocabulary matches, 0.5 if it and another
//! match, 0 otherwise (including an empty intent).

use crate::config::AiaConfig;
use crate::fast_map::FastMap;
use rh_contract::Action;

#[derive(Debug, Clone)]
struct Word {
    text: String,
    prefix: bool,
}

impl Word {
    fn matches(&self, token: &str) -> bool {
        if self.prefix {
            token.starts_with(self.text.as_str())
        } else {
            token == self.text
        }
    }
}

/// A compiled set of phrases, each tagged with a kind, indexed by first word for speed.
#[derive(Debug, Clone, Default)]
pub struct PhraseSet {
    phrases: Vec<(Vec<Word>, u8)>,
    exact_first: FastMap<String, Vec<u32>>,
    prefix_first: Vec<Vec<u32>>, // by first byte
}

impl PhraseSet {
    /// One set of phrases (kind 0).
    pub fn new<S: AsRef<str>>(entries: &[S]) -> PhraseSet {
        PhraseSet::tagged(&[(entries, 0)])
    }

    /// Several vocabularies in one index, each with its kind tag.
    pub fn tagged<S: AsRef<str>>(sets: &[(&[S], u8)]) -> PhraseSet {
        let mut set = PhraseSet {
            prefix_first: vec![Vec::new(); 256],
            ..Default::default()
        };
        for (entries, kind) in sets {
            for e in entries.iter() {
                let words: Vec<Word> = tokenize(&normalize(e.as_ref()), true)
                    .filter_map(|t| match t {
                        Tok::Word(w) => Some(w),
                        Tok::Break => None,
                    })
                    .map(|w| match w.strip_suffix('*') {
                        Some(p) => Word {
                            text: p.trim_matches('*').to_string(),
                            prefix: true,
                        },
                        None => Word {
                            text: w.trim_matches('*').to_string(),
                            prefix: false,
                        },
                    })
                    .collect();
                if words.is_empty() || words.iter().any(|w| w.text.is_empty()) {
                    continue;
                }
                let idx = set.phrases.len() as u32;
                if words[0].prefix {
                    set.prefix_first[words[0].text.as_bytes()[0] as usize].push(idx);
                } else {
                    set.exact_first
                        .entry(words[0].text.clone())
                        .or_default()
                        .push(idx);
                }
                set.phrases.push((words, *kind));
            }
        }
        set
    }

    /// `(kind, length)` of every phrase matching at token `i`.
    fn matches_at(&self, tokens: &[&str], i: usize, out: &mut Vec<(u8, usize)>) {
        out.clear();
        let tok = tokens[i];
        let check = |idx: u32, out: &mut Vec<(u8, usize)>| {
            let (p, kind) = &self.phrases[idx as usize];
            if i + p.len() <= tokens.len() && p.iter().zip(&tokens[i..]).all(|(w, t)| w.matches(t))
            {
                out.push((*kind, p.len()));
            }
        };
        if let Some(list) = self.exact_first.get(tok) {
            for &idx in list {
                check(idx, out);
            }
        }
        if let Some(&b) = tok.as_bytes().first() {
            for &idx in &self.prefix_first[b as usize] {
                check(idx, out);
            }
        }
    }

    /// True when any phrase occurs in the text.
    pub fn any_in(&self, text: &str) -> bool {
        let norm = normalize(text);
        let tokens: Vec<&str> = tokenize(&norm, false)
            .filter_map(|t| match t {
                Tok::Word(w) => Some(w),
                Tok::Break => None,
            })
            .collect();
        let mut buf = Vec::new();
        (0..tokens.len()).any(|i| {
            self.matches_at(&tokens, i, &mut buf);
            !buf.is_empty()
        })
    }
}

fn normalize(text: &str) -> String {
    let mut s = text.to_lowercase();
    if s.contains(['\u{2019}', '\u{2018}']) {
        s = s.replace(['\u{2019}', '\u{2018}'], "'");
    }
    s
}

enum Tok<'a> {
    Word(&'a str),
    Break,
}

/// Splits into words and clause breaks; `star` keeps `*` inside words (vocabulary entries).
fn tokenize(s: &str, star: bool) -> impl Iterator<Item = Tok<'_>> {
    let mut rest = s;
    let is_word = move |c: char| c.is_alphanumeric() || c == '\'' || (star && c == '*');
    std::iter::from_fn(move || loop {
        let c = rest.chars().next()?;
        if is_word(c) {
            let end = rest
                .char_indices()
                .find(|&(_, c)| !is_word(c))
                .map_or(rest.len(), |(i, _)| i);
            let (w, r) = rest.split_at(end);
            rest = r;
            let w = w.trim_matches('\'');
            if !w.is_empty() {
                return Some(Tok::Word(w));
            }
        } else {
            rest = &rest[c.len_utf8()..];
            if matches!(
                c,
                ',' | '.' | ';' | ':' | '!' | '?' | '(' | ')' | '\n' | '[' | ']'
            ) {
                return Some(Tok::Break);
            }
        }
    })
}

const K_NEG: u8 = 3;
const K_BREAK: u8 = 4;

/// The compiled AIA matcher.
#[derive(Debug, Clone)]
pub struct AiaMatcher {
    /// Kinds 0..3 = CATCH, DODGE, NO_ACTION vocabularies; 3 negation cues; 4 clause breaks.
    lexicon: PhraseSet,
    window: usize,
    material: PhraseSet,
    /// Words that coordinate two keywords ("or", "nor") and the words allowed between them.
    coordinators: Vec<String>,
    fillers: Vec<String>,
}

/// Which vocabularies an intent mentions (after negation).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Mentions(pub [bool; 3]);

impl Mentions {
    pub fn has(&self, a: Action) -> bool {
        self.0[a.index()]
    }
}

impl AiaMatcher {
    pub fn new(cfg: &AiaConfig) -> AiaMatcher {
        AiaMatcher {
            lexicon: PhraseSet::tagged(&[
                (cfg.catch.as_slice(), 0),
                (cfg.dodge.as_slice(), 1),
                (cfg.no_action.as_slice(), 2),
                (cfg.negation.as_slice(), K_NEG),
                (cfg.clause_breaks.as_slice(), K_BREAK),
            ]),
            window: cfg.negation_window,
            material: PhraseSet::new(&cfg.material_doubt),
            coordinators: cfg.coordinators.iter().map(|w| normalize(w)).collect(),
            fillers: cfg
                .coordination_fillers
                .iter()
                .map(|w| normalize(w))
                .collect(),
        }
    }

    /// Vocabularies mentioned (non-negated) in the intent.
    pub fn mentions(&self, intent: &str) -> Mentions {
        let norm = normalize(intent);
        let mut tokens: Vec<&str> = Vec::with_capacity(32);
        let mut clause: Vec<u32> = Vec::with_capacity(32);
        let mut c = 0u32;
        for t in tokenize(&norm, false) {
            match t {
                Tok::Word(w) => {
                    tokens.push(w);
                    clause.push(c);
                }
                Tok::Break => c += 1,
            }
        }
        if tokens.is_empty() {
            return Mentions::default();
        }
        let mut buf = Vec::new();
        // Keyword matches (start, len, vocab) and negation cues (start, len).
        let mut kws: Vec<(usize, usize, usize)> = Vec::new();
        let mut all_cues: Vec<(usize, usize)> = Vec::new();
        let mut shift = 0u32;
        for (i, cl) in clause.iter_mut().enumerate() {
            self.lexicon.matches_at(&tokens, i, &mut buf);
            // Clause-break words start a new clause at their position.
            if buf.iter().any(|m| m.0 == K_BREAK) {
                shift += 1;
            }
            *cl += shift;
            for &(kind, len) in &buf {
                match kind {
                    K_NEG => all_cues.push((i, len)),
                    K_BREAK => {}
                    v => kws.push((i, len, v as usize)),
                }
            }
        }
        if kws.is_empty() {
            return Mentions::default();
        }
        // Longest first, then earliest; keep non-overlapping.
        kws.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        let mut kept: Vec<(usize, usize, usize)> = Vec::new();
        for k in kws {
            if kept.iter().all(|q| k.0 + k.1 <= q.0 || q.0 + q.1 <= k.0) {
                kept.push(k);
            }
        }
        kept.sort_by_key(|k| k.0);
        // Negation cues, minus those strictly inside a longer kept keyword.
        let cues: Vec<(usize, usize)> = all_cues
            .into_iter()
            .filter(|&(i, len)| {
                !kept
                    .iter()
                    .any(|q| q.0 <= i && i + len <= q.0 + q.1 && q.1 > len)
            })
            .collect();
        let negates = |cue: (usize, usize), k: (usize, usize, usize)| {
            let cue_end = cue.0 + cue.1;
            cue_end <= k.0 && k.0 - cue_end <= self.window && clause[cue.0] == clause[k.0]
        };
        // Each cue negates the nearest keyword after it (within the window, same clause)
        // and any further ones of that keyword's vocabulary in its reach.
        let mut negated = vec![false; kept.len()];
        let mut active: Vec<(usize, usize)> = Vec::new();
        for &cue in &cues {
            let Some(first) = kept.iter().position(|&k| negates(cue, k)) else {
                continue;
            };
            active.push(cue);
            let vocab = kept[first].2;
            for (j, &k) in kept.iter().enumerate() {
                if negates(cue, k) && k.2 == vocab {
                    negated[j] = true;
                }
            }
            // The negation covers keywords coordinated with the negated one: "don't
            // catch or dodge", "never grab it or step back".
            let mut last = first;
            for j in first + 1..kept.len() {
                let (prev, k) = (kept[last], kept[j]);
                let between = &tokens[prev.0 + prev.1..k.0];
                let coordinated = clause[prev.0] == clause[k.0]
                    && between
                        .iter()
                        .any(|t| self.coordinators.iter().any(|c| c.as_str() == *t))
                    && between
                        .iter()
                        .all(|t| self.fillers.iter().any(|f| f.as_str() == *t));
                if !coordinated {
                    break;
                }
                negated[j] = true;
                last = j;
            }
        }
        let mut m = Mentions::default();
        for (j, &k) in kept.iter().enumerate() {
            // A keyword that is itself an active cue ("avoid" in "avoid catching").
            let is_active_cue = active.iter().any(|&c| c.0 <= k.0 && k.0 + k.1 <= c.0 + c.1);
            if !is_active_cue && !negated[j] {
                m.0[k.2] = true;
            }
        }
        m
    }

    /// AIA score of an intent against the ground-truth action.
    pub fn score(&self, intent: &str, gt: Action) -> f64 {
        aia_from_mentions(self.mentions(intent), gt)
    }

    /// True when the intent questions the object's material or weight.
    pub fn questions_material(&self, intent: &str) -> bool {
        self.material.any_in(intent)
    }
}

/// 1 if only `gt`'s vocabulary matched, 0.5 if it and another did, else 0.
pub fn aia_from_mentions(m: Mentions, gt: Action) -> f64 {
    if !m.has(gt) {
        return 0.0;
    }
    let others = Action::ALL.iter().any(|&a| a != gt && m.has(a));
    if others {
        0.5
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    fn m() -> AiaMatcher {
        AiaMatcher::new(&Config::default().aia)
    }

    fn mentions(s: &str) -> [bool; 3] {
        m().mentions(s).0
    }

    #[test]
    fn plain_keywords() {
        assert_eq!(mentions("I will catch the ball"), [true, false, false]);
        assert_eq!(mentions("Dodging to the left!"), [false, true, false]);
        assert_eq!(mentions("Step back quickly"), [false, true, false]);
        assert_eq!(mentions("Stay still and observe"), [false, false, true]);
        assert_eq!(mentions("No action needed."), [false, false, true]);
        assert_eq!(mentions(""), [false, false, false]);
    }

    #[test]
    fn negation() {
        assert_eq!(
            mentions("Do not catch the knife; step back."),
            [false, true, false]
        );
        assert_eq!(
            mentions("don't try to grab it, retreat"),
            [false, true, false]
        );
        assert_eq!(mentions("Don’t try to grab it"), [false, false, false]);
        assert_eq!(mentions("avoid catching the pan"), [false, false, false]);
        assert_eq!(mentions("avoid the falling lamp"), [false, true, false]);
        assert_eq!(
            mentions("No need to dodge, I'll catch it"),
            [true, false, false]
        );
        assert_eq!(mentions("There is no need to dodge"), [false, false, false]);
        assert_eq!(
            mentions("never try to intercept a knife"),
            [false, false, false]
        );
        // Negation does not cross clause boundaries.
        assert_eq!(mentions("not dangerous, so catch it"), [true, false, false]);
        assert_eq!(
            mentions("I won't dodge but I will catch"),
            [true, false, false]
        );
        // Far-away negation is out of the window.
        assert_eq!(
            mentions("it is not at all heavy or sharp in any way and I catch it"),
            [true, false, false]
        );
        // A negation covers the whole coordinated phrase.
        assert_eq!(mentions("don't catch or dodge"), [false, false, false]);
        assert_eq!(mentions("neither catch nor dodge"), [false, false, false]);
        assert_eq!(
            mentions("do not grab it or step back"),
            [false, false, false]
        );
        assert_eq!(
            mentions("never catch, dodge or sidestep"),
            [false, true, false]
        );
        assert_eq!(
            mentions("don't catch or dodge, just stay put"),
            [false, false, true]
        );
        // Not coordinated: other words between, or "and then" (a new action).
        assert_eq!(
            mentions("don't catch it and then dodge"),
            [false, true, false]
        );
        // Phrases containing a cue word keep their meaning.
        assert_eq!(mentions("do not move"), [false, false, true]);
        assert_eq!(
            mentions("instead of catching it I step aside"),
            [false, true, false]
        );
    }

    #[test]
    fn scores() {
        let m = m();
        assert_eq!(m.score("catch it", Action::Catch), 1.0);
        assert_eq!(m.score("catch it or dodge", Action::Catch), 0.5);
        assert_eq!(m.score("dodge", Action::Catch), 0.0);
        assert_eq!(m.score("do not catch, dodge", Action::Dodge), 1.0);
        assert_eq!(m.score("do not catch, dodge", Action::Catch), 0.0);
        assert_eq!(m.score("don't catch or dodge", Action::Dodge), 0.0);
        assert_eq!(
            m.score("neither catch nor dodge; stay put", Action::NoAction),
            1.0
        );
        assert_eq!(m.score("", Action::NoAction), 0.0);
    }

    #[test]
    fn material_doubt() {
        let m = m();
        assert!(m.questions_material("It may be foam, so catch it"));
        assert!(m.questions_material("This anvil might be heavier than it looks"));
        assert!(m.questions_material("unclear what material it is"));
        assert!(!m.questions_material("catch the apple"));
    }
}
